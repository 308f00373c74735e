#include "render/element_sed_kernel.h"

#include <cstring>

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__ELF__)
#define SEDBRIDGE_SED_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define SEDBRIDGE_SED_CLONES
#endif

namespace sedbridge::render {

SEDBRIDGE_SED_CLONES
void ChunkedElementSeds(size_t elements, int n, const float* slopes, const float* stroke, const double* intercept,
                        const double* mu_Pa, const double* lambda_Pa, double* sed_Pa, float* gradient_t, float* scratch) {
  constexpr int L = kSedLanes, C = kSedStrainComponents, CL = C * L;
  const size_t chunks = SedChunks(elements);
  for (size_t b = 0; b < chunks; ++b) {
    const float* s = slopes + b * size_t(n) * CL;
    const size_t first = b * L;
    const int lanes = int(elements - first < size_t(L) ? elements - first : size_t(L));
    // The strain change: an axpy of 48 floats per actuator (component c, lane l at c L + l).
    alignas(32) float change[CL];
    for (int k = 0; k < CL; ++k) change[k] = 0.0f;
    for (int i = 0; i < n; ++i) {
      const float v = stroke[i];
      const float* si = s + i * CL;
      for (int k = 0; k < CL; ++k) change[k] += si[k] * v;
    }
    // The SED in double (the preload's strain, in the intercept, dwarfs the change).
    alignas(32) double eps[CL], mu[L], lambda[L];
    for (int l = 0; l < L; ++l) {
      const bool live = l < lanes;
      for (int c = 0; c < C; ++c)
        eps[c * L + l] = live ? intercept[(first + size_t(l)) * C + size_t(c)] + double(change[c * L + l]) : 0.0;
      mu[l] = live ? mu_Pa[first + size_t(l)] : 0.0;
      lambda[l] = live ? lambda_Pa[first + size_t(l)] : 0.0;
    }
    alignas(32) double tr[L], w[L];
    for (int l = 0; l < L; ++l) {
      const double* e = eps + l;
      tr[l] = e[0] + e[L] + e[2 * L];
      const double ee = e[0] * e[0] + e[L] * e[L] + e[2 * L] * e[2 * L] +
                        2.0 * (e[3 * L] * e[3 * L] + e[4 * L] * e[4 * L] + e[5 * L] * e[5 * L]);
      w[l] = mu[l] * ee + 0.5 * lambda[l] * tr[l] * tr[l];
    }
    for (int l = 0; l < lanes; ++l) sed_Pa[first + size_t(l)] = w[l];
    if (!gradient_t) continue;
    // dW/deps (shear components count twice in eps:eps), then dW/dstroke_i = dW/deps . slope_i.
    alignas(32) float g[CL];
    for (int l = 0; l < L; ++l) {
      for (int c = 0; c < 3; ++c) g[c * L + l] = float(2.0 * mu[l] * eps[c * L + l] + lambda[l] * tr[l]);
      for (int c = 3; c < C; ++c) g[c * L + l] = float(4.0 * mu[l] * eps[c * L + l]);
    }
    for (int i = 0; i < n; ++i) {
      const float* si = s + i * CL;
      float* out = scratch + i * L;
      for (int l = 0; l < L; ++l) out[l] = g[l] * si[l];
      for (int c = 1; c < C; ++c)
        for (int l = 0; l < L; ++l) out[l] += g[c * L + l] * si[c * L + l];
    }
    for (int l = 0; l < lanes; ++l) {
      float* column = gradient_t + (first + size_t(l)) * size_t(n);
      for (int i = 0; i < n; ++i) column[i] = scratch[i * L + l];
    }
  }
}

// Eight floats, one per vertex of a chunk (a GCC vector: element-wise, the same operations
// as the scalar ones per lane); loaded and stored through memcpy (no alignment assumed).
typedef float FormLanes __attribute__((vector_size(kSedLanes * sizeof(float))));
// (Through references: a vector passed or returned by value changes the ABI without AVX.)
inline __attribute__((always_inline)) void AddLanes(const float* p, float scale, FormLanes& sum) {
  FormLanes v;
  std::memcpy(&v, p, sizeof v);
  sum += v * scale;
}
inline __attribute__((always_inline)) void StoreLanes(float* p, const FormLanes& v) { std::memcpy(p, &v, sizeof v); }

SEDBRIDGE_SED_CLONES
void VertexFormSeds(size_t vertices, int n, const float* forms, const double* constant, const float* u,
                    double* sed_Pa, double* jacobian_t, float* scratch) {
  // One vector lane per vertex, eight vertices a chunk: each lane runs the operations of
  // one vertex alone, in its order, so the answer is the same to the bit as a loop over the
  // vertices; the lanes' sums run side by side instead of one vertex's dependent additions
  // after another's, and a block of Q u stays in registers over the actuators.
  constexpr int L = kSedLanes;
  const size_t stride = VertexFormEntries(n), nl = size_t(n) * L;
  float* q = scratch;  // Q u: component j of lane l at j L + l
  for (size_t c = 0; c < SedChunks(vertices); ++c) {
    const float* g = forms + c * stride * L;
    const float* Q = g + nl;  // column i's lanes at Q + i n L
    size_t k = 0;
    for (; k + 4 * L <= nl; k += 4 * L) {
      FormLanes a0 = {}, a1 = {}, a2 = {}, a3 = {};
      for (int i = 0; i < n; ++i) {
        const float ui = u[i];
        const float* column = Q + size_t(i) * nl + k;
        AddLanes(column, ui, a0), AddLanes(column + L, ui, a1);
        AddLanes(column + 2 * L, ui, a2), AddLanes(column + 3 * L, ui, a3);
      }
      StoreLanes(q + k, a0), StoreLanes(q + k + L, a1), StoreLanes(q + k + 2 * L, a2), StoreLanes(q + k + 3 * L, a3);
    }
    for (; k < nl; k += L) {
      FormLanes a = {};
      for (int i = 0; i < n; ++i) AddLanes(Q + size_t(i) * nl + k, u[i], a);
      StoreLanes(q + k, a);
    }
    // g . u and u . Q u as the vertex-by-vertex loop summed them (the same bits with GCC's
    // x86-64 code): the products of the first n / 4 * 4 actuators rounded before they are
    // added (that part of its loop ran vectorized, an in-order sum of vector products), the
    // rest fused where the CPU has FMA (its scalar tail).
    FormLanes lin = {}, quad = {};
    const int rounded = n / 4 * 4;
    for (int i = 0; i < rounded; ++i) {
      volatile FormLanes product_g, product_q;  // stored: never fused into the sum
      FormLanes v;
      std::memcpy(&v, g + i * L, sizeof v);
      product_g = v * u[i];
      std::memcpy(&v, q + i * L, sizeof v);
      product_q = v * u[i];
      lin += product_g;
      quad += product_q;
    }
    for (int i = rounded; i < n; ++i) AddLanes(g + i * L, u[i], lin), AddLanes(q + i * L, u[i], quad);
    alignas(32) float linear[L], quadratic[L];
    StoreLanes(linear, lin), StoreLanes(quadratic, quad);
    const size_t first = c * L;
    const int lanes = int(vertices - first < size_t(L) ? vertices - first : size_t(L));
    for (int l = 0; l < lanes; ++l)
      sed_Pa[first + size_t(l)] = constant[first + size_t(l)] + double(linear[l]) + double(quadratic[l]);
    if (!jacobian_t) continue;
    for (size_t k = 0; k < nl; ++k) q[k] = g[k] + 2.0f * q[k];
    for (int l = 0; l < lanes; ++l) {
      double* out = jacobian_t + (first + size_t(l)) * size_t(n);
      for (int i = 0; i < n; ++i) out[i] = double(q[i * L + l]);
    }
  }
}

}  // namespace sedbridge::render
