#include "render/element_sed_kernel.h"

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

SEDBRIDGE_SED_CLONES
void VertexFormSeds(size_t vertices, int n, const float* forms, const double* constant, const float* u,
                    double* sed_Pa, double* jacobian_t, float* scratch) {
  const size_t stride = size_t(n) + size_t(n) * size_t(n);
  for (size_t v = 0; v < vertices; ++v) {
    const float* g = forms + v * stride;
    const float* Q = g + n;
    // q = Q u, a column axpy per actuator (vectorized over the column, no horizontal sums).
    for (int j = 0; j < n; ++j) scratch[j] = 0.0f;
    for (int i = 0; i < n; ++i) {
      const float ui = u[i];
      const float* column = Q + size_t(i) * size_t(n);
      for (int j = 0; j < n; ++j) scratch[j] += column[j] * ui;
    }
    float linear = 0.0f, quadratic = 0.0f;
    for (int j = 0; j < n; ++j) linear += g[j] * u[j], quadratic += u[j] * scratch[j];
    sed_Pa[v] = constant[v] + double(linear) + double(quadratic);
    if (!jacobian_t) continue;
    double* out = jacobian_t + v * size_t(n);
    for (int j = 0; j < n; ++j) out[j] = double(g[j] + 2.0f * scratch[j]);
  }
}

}  // namespace sedbridge::render
