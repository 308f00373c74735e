#include "sensors/tactile_forward_model.h"

#include <algorithm>
#include <cmath>
#if (defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)) || defined(SEDBRIDGE_HAVE_LIBMVEC)
#include <immintrin.h>
#endif
#include <sstream>
#include <stdexcept>

#include "sensors/cone_pressure.h"
#include "sensors/flat_punch_pressure.h"

namespace sedbridge::sensors {

namespace {

// Direction component below which the line runs parallel to a side of the square [-]
// (unit-free: d is a direction in mm per unit t); slab clipping then only asks whether the
// line is inside that slab.
constexpr double kParallelDirection = 1e-12;
// "Unbounded" line parameter for the slab clipping [-]: far beyond any pad (mm scale).
constexpr double kUnboundedLineParameter = 1e9;
// Distance below which a sample sits on the taxel centre [mm]: the radial direction is then
// undefined and the radial terms (zero there) are skipped.
constexpr double kOnCentre_mm = 1e-9;

constexpr double kPi = 3.14159265358979323846;
// Taxel sensing area averaged on 3 x 3 points (mid-point rule).
constexpr int kAreaPoints = 3;
// Cells further than this beyond the pad square carry no load (the pad ends there) [mm].
constexpr double kGridMargin_mm = 1.0;

double Rational(const RadialKernel& k, double rho_mm, int order) {
  const double u = rho_mm / k.width_mm;
  const double base = k.gain / std::pow(1.0 + u * u, k.power);
  return order == 0 ? base : order == 1 ? base * u : base * u * u;
}

// Length of the line p + t d inside the square |x|, |y| <= half (slab clipping).
// Length of the line p + t d (|d| = 1), |t| <= half_length, inside the square |x|, |y| <= half.
double LengthInSquare(double px, double py, double dx, double dy, double half,
                      double half_length = kUnboundedLineParameter) {
  double t0 = -half_length, t1 = half_length;
  const double p[2] = {px, py}, d[2] = {dx, dy};
  for (int a = 0; a < 2; ++a) {
    if (std::abs(d[a]) < kParallelDirection) {
      if (std::abs(p[a]) > half) return 0;
      continue;
    }
    double ta = (-half - p[a]) / d[a], tb = (half - p[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return std::max(0.0, t1 - t0);
}

// Fraction of the cell [c - h/2, c + h/2] inside [-half, half] (continuous in half).
// CDF of a unit-area tent of half-width h, at x.
double TentCdf(double x, double h) {
  if (x <= -h) return 0;
  if (x >= h) return 1;
  const double t = (x + h) / h;  // in [0, 2]
  return t <= 1 ? 0.5 * t * t : 1 - 0.5 * (2 - t) * (2 - t);
}
// Share of a tent of half-width h centred at c inside [-half, half].
double TentCoverage(double c, double h, double half) {
  return std::clamp(TentCdf(half - c, h) - TentCdf(-half - c, h), 0.0, 1.0);
}
double Coverage1d(double c, double h, double half) {
  if (std::abs(c) + 0.5 * h <= half) return 1;  // inside: exactly 1, and no division
  const double lo = std::max(c - 0.5 * h, -half), hi = std::min(c + 0.5 * h, half);
  return std::clamp((hi - lo) / h, 0.0, 1.0);
}

}  // namespace

TactileForwardModel::TactileForwardModel(const SensorProfile& profile, const TactileModelParams& params)
    : TactileForwardModel(profile.taxels, profile.taxel_width_mm, profile.taxel_height_mm, params) {
  if (profile.axes != 3)
    throw std::invalid_argument("the tactile forward model needs a three-axis profile ('" + profile.name + "' has " +
                                std::to_string(profile.axes) + " axis)");
}

TactileForwardModel::TactileForwardModel(std::vector<TaxelPosition> taxels, double taxel_width_mm,
                                         double taxel_height_mm, const TactileModelParams& params)
    : taxels_(std::move(taxels)), taxel_w_mm_(taxel_width_mm), taxel_h_mm_(taxel_height_mm), params_(params) {
  if (taxels_.empty()) throw std::invalid_argument("forward model: no taxels");
  if (!(params_.grid_mm > 0) || !(params_.pad_size_mm > 0) || !(params_.contact_modulus_kPa > 0))
    throw std::invalid_argument("forward model: grid_mm, pad_size_mm and contact_modulus_kPa must be > 0");
  CheckKernel(params_.normal, "normal");
  CheckKernel(params_.spread, "spread");
  CheckKernel(params_.shear, "shear");
  CheckKernel(params_.shear_cross, "shear_cross");
  CheckKernel(params_.shear_lift, "shear_lift");
  const double h = params_.grid_mm;
  const double half = 0.5 * params_.pad_size_mm + kGridMargin_mm;
  // Anchor the grid on taxel 0 so that taxel-to-cell offsets of a regular layout are whole
  // multiples of h (the kernel table is then exact, not interpolated).
  const double ax = taxels_[0].x_mm, ay = taxels_[0].y_mm;
  const int below_x = static_cast<int>(std::ceil((ax + half) / h)), below_y = static_cast<int>(std::ceil((ay + half) / h));
  grid_x0_mm_ = ax - below_x * h;
  grid_y0_mm_ = ay - below_y * h;
  grid_n_ = static_cast<int>(std::ceil((half - std::min(grid_x0_mm_, grid_y0_mm_)) / h)) + 1;
  BuildKernelTable();
  // Unit responses of the flat (the largest patch: every pad cell).
  ContactPrimitive flat;
  flat.shape = ContactShape::kFlat;
  flat.normal_force_N = 1;
  std::vector<SurfaceLoad> loads;
  Patch(flat, &loads);
  Respond(loads, &flat_normal_);
  for (auto& l : loads) l.shear_x_N = l.normal_N, l.normal_N = 0;
  Respond(loads, &flat_shear_x_);
  for (auto& l : loads) l.shear_y_N = l.shear_x_N, l.shear_x_N = 0;
  Respond(loads, &flat_shear_y_);
}

Eigen::Vector2d TactileForwardModel::CellCentre_mm(int cell) const {
  const double h = params_.grid_mm;
  return {grid_x0_mm_ + (cell % grid_n_) * h, grid_y0_mm_ + (cell / grid_n_) * h};
}

void TactileForwardModel::BuildKernelTable() {
  const double h = params_.grid_mm;
  double reach = 0;  // largest |taxel - cell| component
  for (const auto& t : taxels_) {
    reach = std::max({reach, std::abs(t.x_mm - grid_x0_mm_), std::abs(t.y_mm - grid_y0_mm_),
                      std::abs(t.x_mm - (grid_x0_mm_ + (grid_n_ - 1) * h)),
                      std::abs(t.y_mm - (grid_y0_mm_ + (grid_n_ - 1) * h))});
  }
  table_half_ = static_cast<int>(std::ceil(reach / h)) + 1;
  table_stride_ = 2 * table_half_ + 1;
  table_.assign(static_cast<size_t>(table_stride_) * table_stride_, KernelEntry{});
  const double wx = taxel_w_mm_ / kAreaPoints, wy = taxel_h_mm_ / kAreaPoints;
  const double inv = 1.0 / (kAreaPoints * kAreaPoints);
  // The kernels at one offset's area points, computed once for the four offsets (+-i, +-j):
  // offset -i's point sx lies at exactly minus the x of offset i's point kAreaPoints-1-sx
  // (IEEE negation and hypot are exact), so each entry sums the very terms, in the same
  // order, it summed when every offset evaluated its own (a quarter of the pow calls: the
  // table was 90 % of a fit-sensor evaluation).
  struct Point {
    double ex, ey, kn, kr, kt, kc, kl;
  };
  Point points[kAreaPoints][kAreaPoints];
  for (int j = 0; j <= table_half_; ++j) {
    for (int i = 0; i <= table_half_; ++i) {
      for (int sy = 0; sy < kAreaPoints; ++sy) {
        for (int sx = 0; sx < kAreaPoints; ++sx) {
          const double dx = i * h + (sx - 0.5 * (kAreaPoints - 1)) * wx;
          const double dy = j * h + (sy - 0.5 * (kAreaPoints - 1)) * wy;
          const double rho = std::hypot(dx, dy);
          Point& pt = points[sy][sx];
          pt.ex = rho > kOnCentre_mm ? dx / rho : 0;
          pt.ey = rho > kOnCentre_mm ? dy / rho : 0;
          pt.kn = Rational(params_.normal, rho, 0);
          pt.kr = Rational(params_.spread, rho, 1);
          pt.kt = Rational(params_.shear, rho, 0);
          pt.kc = Rational(params_.shear_cross, rho, 2);
          pt.kl = Rational(params_.shear_lift, rho, 1);
        }
      }
      for (const int sj : {1, -1}) {
        if (sj < 0 && j == 0) continue;
        for (const int si : {1, -1}) {
          if (si < 0 && i == 0) continue;
          double* out = table_[static_cast<size_t>((si * i + table_half_) + (sj * j + table_half_) * table_stride_)].v;
          for (int sy = 0; sy < kAreaPoints; ++sy) {
            for (int sx = 0; sx < kAreaPoints; ++sx) {
              const Point& pt = points[sj > 0 ? sy : kAreaPoints - 1 - sy][si > 0 ? sx : kAreaPoints - 1 - sx];
              const double ex = si > 0 ? pt.ex : -pt.ex, ey = sj > 0 ? pt.ey : -pt.ey;
              const double kn = pt.kn, kr = pt.kr, kt = pt.kt, kc = pt.kc, kl = pt.kl;
              // normal load -> x, y, z
              out[0] += inv * kr * ex;
              out[1] += inv * kr * ey;
              out[2] += inv * kn;
              // T_x -> x, y, z
              out[kTxX] += inv * (kt + kc * ex * ex);
              out[kTxY] += inv * kc * ey * ex;  // also T_y -> x: the cross term is symmetric
              out[kTxZ] += inv * kl * ex;
              // T_y -> y, z
              out[kTyY] += inv * (kt + kc * ey * ey);
              out[kTyZ] += inv * kl * ey;
            }
          }
        }
      }
    }
  }
  taxel_base_.resize(taxels_.size());
  for (size_t k = 0; k < taxels_.size(); ++k) {
    const int oi = static_cast<int>(std::lround((taxels_[k].x_mm - grid_x0_mm_) / h));
    const int oj = static_cast<int>(std::lround((taxels_[k].y_mm - grid_y0_mm_) / h));
    taxel_base_[k] = (oi + table_half_) + (oj + table_half_) * table_stride_;
  }
}

void TactileForwardModel::TableOffsets(const std::vector<SurfaceLoad>& loads, std::vector<int>* offsets) const {
  offsets->resize(loads.size());
  for (size_t c = 0; c < loads.size(); ++c) {
    const int i = loads[c].cell % grid_n_, j = loads[c].cell / grid_n_;
    (*offsets)[c] = i + j * table_stride_;
  }
}

namespace {
// r[q] = sum_c w[c] (row - offset[c])->v[q], q < 8: most of a forward-model evaluation. The
// portable loop; where the CPU has AVX2 and FMA or AVX-512, the explicit variants below run
// (GCC 12's own x86-64-v3 clone of this loop left a quarter of its FMAs scalar).
void SumKernelRows(const KernelEntry* row, const int* offset, const double* w, int m, double* r) {
  // Four cells at a time into four sets of sums: one set is a chain of dependent FMAs whose
  // latency, not the FMA units, sets the speed.
  double s0[kKernelValues] = {}, s1[kKernelValues] = {}, s2[kKernelValues] = {}, s3[kKernelValues] = {};
  int c = 0;
  for (; c + 3 < m; c += 4) {
    const double* t0 = (row - offset[c])->v;
    const double* t1 = (row - offset[c + 1])->v;
    const double* t2 = (row - offset[c + 2])->v;
    const double* t3 = (row - offset[c + 3])->v;
    const double w0 = w[c], w1 = w[c + 1], w2 = w[c + 2], w3 = w[c + 3];
    for (int q = 0; q < kKernelValues; ++q) {
      s0[q] += w0 * t0[q];
      s1[q] += w1 * t1[q];
      s2[q] += w2 * t2[q];
      s3[q] += w3 * t3[q];
    }
  }
  for (; c < m; ++c) {
    const double* t = (row - offset[c])->v;
    for (int q = 0; q < kKernelValues; ++q) s0[q] += w[c] * t[q];
  }
  for (int q = 0; q < kKernelValues; ++q) r[q] = (s0[q] + s1[q]) + (s2[q] + s3[q]);
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
// The same sums with one 512-bit register per set: an entry is one cache line, eight
// doubles, so a (taxel, cell) pair is one load and one FMA instead of two of each (the AVX2
// variant). Same products, same order: the same sums as SumKernelRowsAvx2, bit for bit.
__attribute__((target("avx512f"))) void SumKernelRowsAvx512(const KernelEntry* row, const int* offset,
                                                           const double* w, int m, double* r) {
  static_assert(kKernelValues == 8 && sizeof(KernelEntry) == 64, "one entry, one 512-bit register");
  __m512d s0 = _mm512_setzero_pd(), s1 = _mm512_setzero_pd(), s2 = _mm512_setzero_pd(), s3 = _mm512_setzero_pd();
  int c = 0;
  for (; c + 3 < m; c += 4) {
    s0 = _mm512_fmadd_pd(_mm512_set1_pd(w[c]), _mm512_load_pd((row - offset[c])->v), s0);
    s1 = _mm512_fmadd_pd(_mm512_set1_pd(w[c + 1]), _mm512_load_pd((row - offset[c + 1])->v), s1);
    s2 = _mm512_fmadd_pd(_mm512_set1_pd(w[c + 2]), _mm512_load_pd((row - offset[c + 2])->v), s2);
    s3 = _mm512_fmadd_pd(_mm512_set1_pd(w[c + 3]), _mm512_load_pd((row - offset[c + 3])->v), s3);
  }
  for (; c < m; ++c) s0 = _mm512_fmadd_pd(_mm512_set1_pd(w[c]), _mm512_load_pd((row - offset[c])->v), s0);
  _mm512_storeu_pd(r, _mm512_add_pd(_mm512_add_pd(s0, s1), _mm512_add_pd(s2, s3)));
}

// The same with two 256-bit registers per set (an entry's two halves). GCC 12's x86-64-v3
// clone of SumKernelRows vectorized only three of its four sets and ran the fourth as eight
// scalar FMAs, 14 FMA instructions per four cells instead of 8. Same products, same order
// (FMA per value): the same sums as that clone was, bit for bit.
__attribute__((target("avx2,fma"))) void SumKernelRowsAvx2(const KernelEntry* row, const int* offset, const double* w,
                                                          int m, double* r) {
  static_assert(kKernelValues == 8, "an entry is two 256-bit halves");
  __m256d a0 = _mm256_setzero_pd(), b0 = _mm256_setzero_pd(), a1 = _mm256_setzero_pd(), b1 = _mm256_setzero_pd();
  __m256d a2 = _mm256_setzero_pd(), b2 = _mm256_setzero_pd(), a3 = _mm256_setzero_pd(), b3 = _mm256_setzero_pd();
  int c = 0;
  for (; c + 3 < m; c += 4) {
    const double* t0 = (row - offset[c])->v;
    const double* t1 = (row - offset[c + 1])->v;
    const double* t2 = (row - offset[c + 2])->v;
    const double* t3 = (row - offset[c + 3])->v;
    const __m256d w0 = _mm256_set1_pd(w[c]), w1 = _mm256_set1_pd(w[c + 1]);
    const __m256d w2 = _mm256_set1_pd(w[c + 2]), w3 = _mm256_set1_pd(w[c + 3]);
    a0 = _mm256_fmadd_pd(w0, _mm256_load_pd(t0), a0);
    b0 = _mm256_fmadd_pd(w0, _mm256_load_pd(t0 + 4), b0);
    a1 = _mm256_fmadd_pd(w1, _mm256_load_pd(t1), a1);
    b1 = _mm256_fmadd_pd(w1, _mm256_load_pd(t1 + 4), b1);
    a2 = _mm256_fmadd_pd(w2, _mm256_load_pd(t2), a2);
    b2 = _mm256_fmadd_pd(w2, _mm256_load_pd(t2 + 4), b2);
    a3 = _mm256_fmadd_pd(w3, _mm256_load_pd(t3), a3);
    b3 = _mm256_fmadd_pd(w3, _mm256_load_pd(t3 + 4), b3);
  }
  for (; c < m; ++c) {
    const double* t = (row - offset[c])->v;
    const __m256d wc = _mm256_set1_pd(w[c]);
    a0 = _mm256_fmadd_pd(wc, _mm256_load_pd(t), a0);
    b0 = _mm256_fmadd_pd(wc, _mm256_load_pd(t + 4), b0);
  }
  _mm256_storeu_pd(r, _mm256_add_pd(_mm256_add_pd(a0, a1), _mm256_add_pd(a2, a3)));
  _mm256_storeu_pd(r + 4, _mm256_add_pd(_mm256_add_pd(b0, b1), _mm256_add_pd(b2, b3)));
}

using SumKernelRowsFn = void (*)(const KernelEntry*, const int*, const double*, int, double*);
// Chosen once: AVX-512 where the CPU has it, else AVX2 with FMA, else the portable loop.
SumKernelRowsFn PickSumKernelRows() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) return SumKernelRowsAvx512;
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return SumKernelRowsAvx2;
  return SumKernelRows;
}
#else
using SumKernelRowsFn = void (*)(const KernelEntry*, const int*, const double*, int, double*);
SumKernelRowsFn PickSumKernelRows() { return SumKernelRows; }
#endif

// The fields stored one by one: a braced SurfaceLoad is built on the stack by scalar stores
// and copied by 16-byte loads, which stall on store forwarding (a third of a rod's patch).
void AddLoad(std::vector<SurfaceLoad>* loads, int cell, double normal_N) {
  SurfaceLoad& l = loads->emplace_back();
  l.cell = cell;
  l.normal_N = normal_N;
}

// Integral of sqrt(1 - u^2) over [lo, hi], -1 <= lo < hi <= 1, hi - lo <= 1, with one
// arcsine: asin(hi) - asin(lo) = asin(hi sqrt(1 - lo^2) - lo sqrt(1 - hi^2)), which holds
// when lo hi >= 0 or lo^2 + hi^2 <= 1 (here: lo < 0 < hi and hi - lo <= 1 give the
// latter). The arcsines are most of a rod's patch.
double HalfDiscStrip(double lo, double hi) {
  const double c_lo = std::sqrt(std::max(0.0, 1 - lo * lo)), c_hi = std::sqrt(std::max(0.0, 1 - hi * hi));
  return 0.5 * (hi * c_hi - lo * c_lo + std::asin(std::clamp(hi * c_lo - lo * c_hi, -1.0, 1.0)));
}

// HalfDiscStrip of n strips: out[q] = HalfDiscStrip(lo[q], hi[q]). Two at a time through
// glibc's vector arcsine (libmvec, within 4 ulp of the scalar one) where it is linked: the
// scalar arcsine was a fifth of a rod's evaluation.
#if defined(SEDBRIDGE_HAVE_LIBMVEC)
extern "C" __m128d _ZGVbN2v_asin(__m128d);  // libmvec's SSE variant of asin (glibc >= 2.35)
void HalfDiscStrips(const double* lo, const double* hi, double* out, int n) {
  int q = 0;
  const __m128d zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0), minus_one = _mm_set1_pd(-1.0);
  const __m128d half = _mm_set1_pd(0.5);
  for (; q + 1 < n; q += 2) {
    const __m128d l = _mm_loadu_pd(lo + q), u = _mm_loadu_pd(hi + q);
    const __m128d c_lo = _mm_sqrt_pd(_mm_max_pd(zero, _mm_sub_pd(one, _mm_mul_pd(l, l))));
    const __m128d c_hi = _mm_sqrt_pd(_mm_max_pd(zero, _mm_sub_pd(one, _mm_mul_pd(u, u))));
    const __m128d arg = _mm_min_pd(one, _mm_max_pd(minus_one, _mm_sub_pd(_mm_mul_pd(u, c_lo), _mm_mul_pd(l, c_hi))));
    const __m128d sum = _mm_add_pd(_mm_sub_pd(_mm_mul_pd(u, c_hi), _mm_mul_pd(l, c_lo)), _ZGVbN2v_asin(arg));
    _mm_storeu_pd(out + q, _mm_mul_pd(half, sum));
  }
  for (; q < n; ++q) out[q] = HalfDiscStrip(lo[q], hi[q]);
}
#else
void HalfDiscStrips(const double* lo, const double* hi, double* out, int n) {
  for (int q = 0; q < n; ++q) out[q] = HalfDiscStrip(lo[q], hi[q]);
}
#endif

// A rod's patch before its strips are integrated: per cell, its strip across the axis in
// units of the half-width, and the rest of its weight (the rod's ends, the pad's edge).
struct RodStrips {
  int size = 0;
  std::vector<int> cell;
  std::vector<double> lo, hi, ends, edge_x, edge_y, integral;
  // Room for `more` strips after the first `size` (never shrinks: a thread's buffers).
  void Reserve(int more) {
    const size_t n = static_cast<size_t>(size + more);
    if (cell.size() >= n) return;
    for (auto* v : {&lo, &hi, &ends, &edge_x, &edge_y, &integral}) v->resize(2 * n);
    cell.resize(2 * n);
  }
};
}  // namespace

void TactileForwardModel::Patch(const ContactPrimitive& c, std::vector<SurfaceLoad>* loads) const {
  loads->clear();
  if (!(c.normal_force_N > 0) || !std::isfinite(c.normal_force_N)) return;
  const double h = params_.grid_mm, half = 0.5 * params_.pad_size_mm;
  const double F = c.normal_force_N;
  auto add_box = [&](double x_lo, double x_hi, double y_lo, double y_hi, auto&& weight) {
    const int i0 = std::max(0, static_cast<int>(std::floor((x_lo - grid_x0_mm_) / h)));
    const int i1 = std::min(grid_n_ - 1, static_cast<int>(std::ceil((x_hi - grid_x0_mm_) / h)));
    const int j0 = std::max(0, static_cast<int>(std::floor((y_lo - grid_y0_mm_) / h)));
    const int j1 = std::min(grid_n_ - 1, static_cast<int>(std::ceil((y_hi - grid_y0_mm_) / h)));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const double x = grid_x0_mm_ + i * h, y = grid_y0_mm_ + j * h;
        const double w = weight(x, y) * Coverage1d(x, h, half + kGridMargin_mm) * Coverage1d(y, h, half + kGridMargin_mm);
        if (w > 0) AddLoad(loads, i + j * grid_n_, w);
      }
  };
  switch (c.shape) {
    case ContactShape::kSphere: {
      const double a = SphereHalfWidth_mm(F, c.radius_mm);
      add_box(c.x_mm - a, c.x_mm + a, c.y_mm - a, c.y_mm + a, [&](double x, double y) {
        const double r2 = ((x - c.x_mm) * (x - c.x_mm) + (y - c.y_mm) * (y - c.y_mm)) / (a * a);
        return r2 < 1 ? std::sqrt(1 - r2) : 0.0;
      });
      break;
    }
    case ContactShape::kCylinder: {
      const double yaw = c.yaw_deg * kPi / 180.0, dx = std::cos(yaw), dy = std::sin(yaw);
      // A finite rod: its half-length along the axis from (x, y); an infinite one: none.
      const double half_length = c.length_mm > 0 ? 0.5 * c.length_mm : kUnboundedLineParameter;
      const double L = LengthInSquare(c.x_mm, c.y_mm, dx, dy, half, half_length);
      if (L <= 0) return;
      const double b = RodHalfWidth_mm(F / L, c.radius_mm);
      // The Hertz profile averaged over [s - h/2, s + h/2] across the axis, not sampled at
      // the cell centre: a strip only a few cells wide, point-sampled, gains or loses a
      // cell with a sqrt-kink as b grows, which made the readings (and chi^2) rough in R
      // at the noise level of a hold's mean (jumps of tens in chi^2 between R and 1.05 R).
      const double t_half = 0.5 * h / b, inv_b = 1 / b;
      // Two passes: the cells of the band with their strip [lo, hi] across the axis and the
      // rest of their weight, then every strip's integral at once (HalfDiscStrips: its
      // arcsines in vector calls where the C library has them, most of a rod's patch).
      thread_local RodStrips strips;
      strips.size = 0;
      // Only the band |s| < b around the axis, row by row (or column by column for a rod
      // closer to the x axis), not the whole pad.
      const bool by_rows = std::abs(dy) >= std::abs(dx);
      for (int line = 0; line < grid_n_; ++line) {
        const double along = (by_rows ? grid_y0_mm_ : grid_x0_mm_) + line * h;
        if (std::abs(along) > half + h) continue;
        const double slope = by_rows ? -dy : dx;  // ds per unit of the scanned coordinate
        const double centre = by_rows ? c.x_mm + (along - c.y_mm) * dx / dy : c.y_mm + (along - c.x_mm) * dy / dx;
        const double reach = b / std::abs(slope) + h;
        const double lo_s = centre - reach, hi_s = centre + reach;
        const double origin = by_rows ? grid_x0_mm_ : grid_y0_mm_;
        const int k0 = std::max(0, static_cast<int>(std::floor((lo_s - origin) / h)));
        const int k1 = std::min(grid_n_ - 1, static_cast<int>(std::ceil((hi_s - origin) / h)));
        if (k1 < k0) continue;
        strips.Reserve(k1 - k0 + 1);
        int n = strips.size;
        int* cell = strips.cell.data();
        double *s_lo = strips.lo.data(), *s_hi = strips.hi.data(), *s_ends = strips.ends.data();
        double *s_ex = strips.edge_x.data(), *s_ey = strips.edge_y.data();
        for (int k = k0; k <= k1; ++k) {
          const int i = by_rows ? k : line, j = by_rows ? line : k;
          const double x = grid_x0_mm_ + i * h, y = grid_y0_mm_ + j * h;
          // The Hertz profile averaged over [s - h/2, s + h/2] across the axis, not sampled
          // at the cell centre: a strip only a few cells wide, point-sampled, gains or loses
          // a cell with a sqrt-kink as b grows, which made the readings (and chi^2) rough in
          // R at the noise level of a hold's mean (jumps of tens in chi^2 between R and 1.05 R).
          const double t = (-(x - c.x_mm) * dy + (y - c.y_mm) * dx) * inv_b;
          const double lo = std::max(-1.0, t - t_half), hi = std::min(1.0, t + t_half);
          if (hi <= lo) continue;
          // A finite rod's ends: the cell's share of [-half_length, half_length] along the
          // axis, for a tent-shaped cell (half-width h): the tents sum to one along the axis,
          // so the loaded length is exact, and the share is C1 in the ends' positions (a
          // box-shaped cell's share kinks at every cell boundary, which a hold's mean sees).
          const double ends = c.length_mm > 0 ? TentCoverage((x - c.x_mm) * dx + (y - c.y_mm) * dy, h, half_length) : 1.0;
          if (!(ends > 0)) continue;
          cell[n] = i + j * grid_n_;
          s_lo[n] = lo;
          s_hi[n] = hi;
          s_ends[n] = ends;
          s_ex[n] = Coverage1d(x, h, half);
          s_ey[n] = Coverage1d(y, h, half);
          ++n;
        }
        strips.size = n;
      }
      const int m = strips.size;
      loads->reserve(static_cast<size_t>(m));
      HalfDiscStrips(strips.lo.data(), strips.hi.data(), strips.integral.data(), m);
      for (int q = 0; q < m; ++q) {
        const size_t u = static_cast<size_t>(q);
        const double w = strips.integral[u] * strips.ends[u] * strips.edge_x[u] * strips.edge_y[u];
        if (w > 0) AddLoad(loads, strips.cell[static_cast<size_t>(q)], w);
      }
      break;
    }
    case ContactShape::kPunch:
    case ContactShape::kRoundPunch:
      SplatFlatPunch(FlatPunchOf(c), {grid_x0_mm_, grid_y0_mm_}, h, grid_n_, loads);
      break;
    case ContactShape::kCorner:
      SplatCone(c.x_mm, c.y_mm, CornerRadius_mm(F), F, {grid_x0_mm_, grid_y0_mm_}, h, grid_n_, loads);
      break;
    case ContactShape::kFlat:
      add_box(-half, half, -half, half,
              [&](double x, double y) { return Coverage1d(x, h, half) * Coverage1d(y, h, half); });
      break;
  }
  double sum = 0;
  for (const auto& l : *loads) sum += l.normal_N;
  if (!(sum > 0)) {
    loads->clear();
    return;
  }
  const double tx = c.shear_x_N / F, ty = c.shear_y_N / F;
  for (auto& l : *loads) {
    l.normal_N *= F / sum;
    l.shear_x_N = tx * l.normal_N;
    l.shear_y_N = ty * l.normal_N;
  }
}

double TactileForwardModel::SphereHalfWidth_mm(double force_N, double radius_mm) const {
  const double E_N_mm2 = params_.contact_modulus_kPa * 1e-3;  // kPa -> N/mm^2
  const double R = std::max(radius_mm, 1e-3);
  return std::hypot(std::cbrt(3.0 * force_N * R / (4.0 * E_N_mm2)), params_.grid_mm);
}

double TactileForwardModel::CornerRadius_mm(double force_N) const {
  // Widened as a rod's band: the cover spreads a sharp contact over a width of its own.
  return std::hypot(ConeContactRadius_mm(force_N, params_.contact_modulus_kPa, kCubeCornerConeTan),
                    std::max(params_.grid_mm, params_.rod_min_halfwidth_mm));
}

double TactileForwardModel::RodHalfWidth_mm(double force_per_length_N_mm, double radius_mm) const {
  const double E_N_mm2 = params_.contact_modulus_kPa * 1e-3;
  const double R = std::max(radius_mm, 1e-3);
  return std::hypot(std::sqrt(4.0 * force_per_length_N_mm * R / (kPi * E_N_mm2)),
                    std::max(params_.grid_mm, params_.rod_min_halfwidth_mm));
}

double TactileForwardModel::PatchCellsEstimate(const ContactPrimitive& c) const {
  if (!(c.normal_force_N > 0) || !std::isfinite(c.normal_force_N)) return 0;
  const double h = params_.grid_mm, F = c.normal_force_N;
  const double grid_area = cell_count() * h * h;
  switch (c.shape) {
    case ContactShape::kSphere: {  // Patch's disc
      const double a = SphereHalfWidth_mm(F, c.radius_mm);
      return std::min(kPi * a * a, grid_area) / (h * h);
    }
    case ContactShape::kCylinder: {  // Patch's band, 2 b wide along the axis over the pad
      const double L = RodLengthOnPad_mm(c);
      if (!(L > 0)) return 0;
      const double b = RodHalfWidth_mm(F / L, c.radius_mm);
      return std::min(2.0 * b * (L + 2.0 * kGridMargin_mm), grid_area) / (h * h);
    }
    case ContactShape::kPunch:  // the face's cells and a ring of the splat's around it
      return std::min(4.0 * (c.half_size_mm[0] + 0.5 * h) * (c.half_size_mm[1] + 0.5 * h), grid_area) / (h * h);
    case ContactShape::kRoundPunch:  // the same for a disc
      return std::min(kPi * (c.radius_mm + 0.5 * h) * (c.radius_mm + 0.5 * h), grid_area) / (h * h);
    case ContactShape::kCorner: {  // the cone's disc and the splat's ring of cells around it
      const double a = CornerRadius_mm(F) + h;
      return std::min(kPi * a * a, grid_area) / (h * h);
    }
    default: return 0;
  }
}

double TactileForwardModel::RodLengthOnPad_mm(const ContactPrimitive& c) const {
  if (c.shape != ContactShape::kCylinder) return 0;
  const double yaw = c.yaw_deg * kPi / 180.0;
  return LengthInSquare(c.x_mm, c.y_mm, std::cos(yaw), std::sin(yaw), 0.5 * params_.pad_size_mm,
                        c.length_mm > 0 ? 0.5 * c.length_mm : kUnboundedLineParameter);
}

void TactileForwardModel::Predict(const ContactPrimitive& c, Eigen::VectorXd* readings_N) const {
  if (c.shape == ContactShape::kFlat && flat_normal_.size() > 0) {
    if (!(c.normal_force_N > 0) || !std::isfinite(c.normal_force_N)) {
      readings_N->setZero(3 * taxel_count());
      return;
    }
    *readings_N = c.normal_force_N * flat_normal_ + c.shear_x_N * flat_shear_x_ + c.shear_y_N * flat_shear_y_;
    return;
  }
  thread_local std::vector<SurfaceLoad> loads;
  Patch(c, &loads);
  Respond(loads, readings_N);
}

void TactileForwardModel::PredictLinearInShear(const ContactPrimitive& c, Eigen::VectorXd* normal_part,
                                               Eigen::VectorXd* per_shear_x, Eigen::VectorXd* per_shear_y,
                                               int* patch_cells) const {
  if (patch_cells) *patch_cells = 0;
  const int n = taxel_count();
  normal_part->setZero(3 * n);
  per_shear_x->setZero(3 * n);
  per_shear_y->setZero(3 * n);
  if (!(c.normal_force_N > 0) || !std::isfinite(c.normal_force_N)) return;
  if (c.shape == ContactShape::kFlat && flat_normal_.size() > 0) {
    *normal_part = c.normal_force_N * flat_normal_;
    *per_shear_x = flat_shear_x_;
    *per_shear_y = flat_shear_y_;
    return;
  }
  thread_local std::vector<SurfaceLoad> loads;
  ContactPrimitive normal_only = c;
  normal_only.shear_x_N = normal_only.shear_y_N = 0;
  Patch(normal_only, &loads);
  if (patch_cells) *patch_cells = static_cast<int>(loads.size());
  if (loads.empty()) return;
  // One pass: the 9 kernel values of every (taxel, cell) times the cell's share of the force.
  const double inv_F = 1.0 / c.normal_force_N;
  double* a = normal_part->data();
  double* bx = per_shear_x->data();
  double* by = per_shear_y->data();
  thread_local std::vector<int> offsets;
  thread_local std::vector<double> weights;
  TableOffsets(loads, &offsets);
  const int m = static_cast<int>(loads.size());
  weights.resize(loads.size());
  for (int c_i = 0; c_i < m; ++c_i) weights[static_cast<size_t>(c_i)] = loads[static_cast<size_t>(c_i)].normal_N;
  static const SumKernelRowsFn kSumKernelRows = PickSumKernelRows();
  for (int k = 0; k < n; ++k) {
    double r[kKernelValues];
    kSumKernelRows(&table_[static_cast<size_t>(taxel_base_[k])], offsets.data(), weights.data(), m, r);
    for (int q = 0; q < 3; ++q) a[3 * k + q] = r[kNormalX + q];
    bx[3 * k] = r[kTxX] * inv_F, bx[3 * k + 1] = r[kTxY] * inv_F, bx[3 * k + 2] = r[kTxZ] * inv_F;
    by[3 * k] = r[kTxY] * inv_F, by[3 * k + 1] = r[kTyY] * inv_F, by[3 * k + 2] = r[kTyZ] * inv_F;
  }
}

void TactileForwardModel::Respond(const std::vector<SurfaceLoad>& loads, Eigen::VectorXd* readings_N) const {
  const int n = taxel_count();
  readings_N->setZero(3 * n);
  if (loads.empty()) return;
  bool shear = false;
  for (const auto& l : loads) shear = shear || l.shear_x_N != 0 || l.shear_y_N != 0;
  double* out = readings_N->data();
  thread_local std::vector<int> offsets;
  TableOffsets(loads, &offsets);
  const size_t m = loads.size();
  for (int k = 0; k < n; ++k) {
    double rx = 0, ry = 0, rz = 0;
    const KernelEntry* row = &table_[static_cast<size_t>(taxel_base_[k])];
    for (size_t c_i = 0; c_i < m; ++c_i) {
      const SurfaceLoad& l = loads[c_i];
      const double* t = (row - offsets[c_i])->v;
      const double P = l.normal_N;
      rx += P * t[kNormalX];
      ry += P * t[kNormalY];
      rz += P * t[kNormalZ];
      if (shear) {
        rx += l.shear_x_N * t[kTxX] + l.shear_y_N * t[kTxY];
        ry += l.shear_x_N * t[kTxY] + l.shear_y_N * t[kTyY];
        rz += l.shear_x_N * t[kTxZ] + l.shear_y_N * t[kTyZ];
      }
    }
    out[3 * k] = rx;
    out[3 * k + 1] = ry;
    out[3 * k + 2] = rz;
  }
}

}  // namespace sedbridge::sensors
