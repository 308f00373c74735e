#include "sensors/flat_punch_pressure.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "sensors/grid_splat.h"

namespace sedbridge::sensors {
namespace {

// Integral of min(1 / sqrt(1 - (s/a)^2), cap) ds from 0 to s (s in [0, a]), the cap applying
// beyond s_c = a sqrt(1 - 1/cap^2), rounding_mm from the edge.
double CappedStripIntegral(double s, double a, double rounding_mm) {
  const double s_c = std::max(a - rounding_mm, 0.0);
  const double cap = 1 / std::sqrt(std::max(1 - (s_c / a) * (s_c / a), 1e-300));
  if (s <= s_c) return a * std::asin(std::min(s / a, 1.0));
  return a * std::asin(s_c / a) + cap * (s - s_c);
}

// Signed version over [lo, hi] within [-a, a].
double StripWeight(double lo, double hi, double a, double rounding_mm) {
  auto f = [&](double s) { return std::copysign(CappedStripIntegral(std::abs(s), a, rounding_mm), s); };
  return f(hi) - f(lo);
}

// Integral over r in [0, r] of min(r / sqrt(a^2 - r^2), cap r) dr (the round punch's
// pressure times r, capped rounding_mm inside the edge), without the 2 pi.
double CappedRingIntegral(double r, double a, double rounding_mm) {
  const double r_c = std::max(a - rounding_mm, 0.0);
  const double cap = 1 / std::sqrt(std::max(a * a - r_c * r_c, 1e-300));
  if (r <= r_c) return a - std::sqrt(std::max(a * a - r * r, 0.0));
  return a - std::sqrt(a * a - r_c * r_c) + 0.5 * cap * (r * r - r_c * r_c);
}

}  // namespace

std::vector<SurfaceLoad> FlatPunchLoads(const TactileForwardModel& model, const FlatPunch& punch) {
  const double a = punch.half_size_mm[0], b = punch.round ? a : punch.half_size_mm[1];
  if (!(a > 0 && b > 0) || !(punch.rounding_mm >= 0) || !(punch.normal_force_N >= 0))
    throw std::invalid_argument("FlatPunchLoads: half sizes must be > 0, rounding and force >= 0");
  const double h = model.cell_size_mm(), strip = 0.25 * h;
  const Eigen::Vector2d origin = model.CellCentre_mm(0);
  const double c = std::cos(punch.yaw_deg * M_PI / 180), s = std::sin(punch.yaw_deg * M_PI / 180);
  std::map<int, double> cells;
  double total = 0;
  auto deposit = [&](double u, double v, double w) {  // punch frame point, weight
    total += w;
    const double x = punch.x_mm + c * u - s * v, y = punch.y_mm + s * u + c * v;
    const long col = std::lround((x - origin.x()) / h), row = std::lround((y - origin.y()) / h);
    if (col < 0 || row < 0 || col >= model.grid_n() || row >= model.grid_n()) return;
    cells[int(row) * model.grid_n() + int(col)] += w;
  };
  if (punch.round) {
    const int rings = std::max(1, int(std::ceil(a / strip)));
    for (int i = 0; i < rings; ++i) {
      const double r0 = a * i / rings, r1 = a * (i + 1) / rings, rm = 0.5 * (r0 + r1);
      const double w = CappedRingIntegral(r1, a, punch.rounding_mm) - CappedRingIntegral(r0, a, punch.rounding_mm);
      const int sectors = std::max(1, int(std::ceil(2 * M_PI * rm / strip)));
      for (int k = 0; k < sectors; ++k) {
        const double t = 2 * M_PI * (k + 0.5) / sectors;
        deposit(rm * std::cos(t), rm * std::sin(t), w / sectors);
      }
    }
  } else {
    const int nu = std::max(1, int(std::ceil(2 * a / strip))), nv = std::max(1, int(std::ceil(2 * b / strip)));
    std::vector<double> wv(size_t(nv), 0.0);
    for (int j = 0; j < nv; ++j)
      wv[size_t(j)] = StripWeight(-b + 2 * b * j / nv, -b + 2 * b * (j + 1) / nv, b, punch.rounding_mm);
    for (int i = 0; i < nu; ++i) {
      const double u0 = -a + 2 * a * i / nu, u1 = -a + 2 * a * (i + 1) / nu;
      const double wu = StripWeight(u0, u1, a, punch.rounding_mm);
      for (int j = 0; j < nv; ++j) deposit(0.5 * (u0 + u1), -b + b * (2 * j + 1) / nv, wu * wv[size_t(j)]);
    }
  }
  std::vector<SurfaceLoad> loads;
  if (!(total > 0)) return loads;
  for (const auto& [cell, w] : cells) loads.push_back({cell, punch.normal_force_N * w / total, 0, 0});
  return loads;
}

FlatPunch FlatPunchOf(const ContactPrimitive& c) {
  FlatPunch punch;
  punch.x_mm = c.x_mm;
  punch.y_mm = c.y_mm;
  punch.round = c.shape == ContactShape::kRoundPunch;
  punch.half_size_mm[0] = punch.round ? c.radius_mm : c.half_size_mm[0];
  punch.half_size_mm[1] = punch.round ? c.radius_mm : c.half_size_mm[1];
  punch.yaw_deg = c.yaw_deg;
  punch.normal_force_N = c.normal_force_N;
  return punch;
}

void SplatFlatPunch(const FlatPunch& punch, const Eigen::Vector2d& origin, double h, int n,
                    std::vector<SurfaceLoad>* loads) {
  const double a = punch.half_size_mm[0], b = punch.round ? a : punch.half_size_mm[1];
  if (!(a > 0 && b > 0) || !(punch.normal_force_N > 0) || !(h > 0) || n <= 0) return;
  const double rounding = std::max(punch.rounding_mm, 0.0);
  const double c = std::cos(punch.yaw_deg * M_PI / 180), s = std::sin(punch.yaw_deg * M_PI / 180);
  GridSplat splat(origin, h, n);
  // Face coordinates (u along the first side, v the second) to the pad.
  auto deposit = [&](double u, double v, double w) {
    splat.Deposit(punch.x_mm + c * u - s * v, punch.y_mm + s * u + c * v, w);
  };
  constexpr int m = kPunchStripsPerSide;
  if (punch.round) {
    constexpr int rings = m / 2;
    for (int i = 0; i < rings; ++i) {
      const double r0 = a * i / rings, r1 = a * (i + 1) / rings, rm = 0.5 * (r0 + r1);
      const double w = CappedRingIntegral(r1, a, rounding) - CappedRingIntegral(r0, a, rounding);
      const int sectors = 4 * (i + 1);
      for (int k = 0; k < sectors; ++k) {
        const double t = 2 * M_PI * (k + 0.5) / sectors;
        deposit(rm * std::cos(t), rm * std::sin(t), w / sectors);
      }
    }
  } else {
    double wu[m], wv[m];
    for (int j = 0; j < m; ++j) {
      wu[j] = StripWeight(-a + 2 * a * j / m, -a + 2 * a * (j + 1) / m, a, rounding);
      wv[j] = StripWeight(-b + 2 * b * j / m, -b + 2 * b * (j + 1) / m, b, rounding);
    }
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) deposit(-a + a * (2 * i + 1) / m, -b + b * (2 * j + 1) / m, wu[i] * wv[j]);
  }
  splat.Emit(punch.normal_force_N, loads);
}

}  // namespace sedbridge::sensors
