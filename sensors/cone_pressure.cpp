#include "sensors/cone_pressure.h"

#include <algorithm>
#include <cmath>

namespace sedbridge::sensors {

double ConeContactRadius_mm(double force_N, double contact_modulus_kPa, double tan_beta) {
  const double E_N_mm2 = contact_modulus_kPa * 1e-3;
  if (!(force_N > 0) || !(E_N_mm2 > 0) || !(tan_beta > 0)) return 0;
  return std::sqrt(2 * force_N / (M_PI * E_N_mm2 * tan_beta));
}

double ConeForceShareWithin(double r_mm, double a_mm) {
  if (!(a_mm > 0)) return 1;
  const double t = std::clamp(r_mm / a_mm, 0.0, 1.0);
  if (t <= 0) return 0;
  return t * t * std::acosh(1 / t) + 1 - std::sqrt(1 - t * t);
}

void SplatCone(double x_mm, double y_mm, double a_mm, double force_N, const Eigen::Vector2d& origin, double h, int n,
               std::vector<SurfaceLoad>* loads) {
  if (!(force_N > 0) || !(a_mm >= 0) || !(h > 0) || n <= 0) return;
  // Dense accumulation over the grid, the touched cells listed (a thread's buffers).
  thread_local std::vector<double> grid;
  thread_local std::vector<int> touched;
  grid.assign(size_t(n) * size_t(n), 0.0);
  touched.clear();
  double total = 0;
  auto add = [&](int col, int row, double w) {
    if (col < 0 || row < 0 || col >= n || row >= n || !(w > 0)) return;
    double& g = grid[size_t(row) * size_t(n) + size_t(col)];
    if (g == 0) touched.push_back(row * n + col);
    g += w;
  };
  auto deposit = [&](double u, double v, double w) {
    total += w;
    const double gx = (x_mm + u - origin.x()) / h, gy = (y_mm + v - origin.y()) / h;
    const double fx = std::floor(gx), fy = std::floor(gy), tx = gx - fx, ty = gy - fy;
    const int i = int(fx), j = int(fy);
    add(i, j, w * (1 - tx) * (1 - ty));
    add(i + 1, j, w * tx * (1 - ty));
    add(i, j + 1, w * (1 - tx) * ty);
    add(i + 1, j + 1, w * tx * ty);
  };
  // Rings of a fixed count (the loads do not jump as a changes); the innermost carries the
  // logarithmic peak's share, deposited at its mid-radius like the rest.
  constexpr int rings = 12;
  double below = 0;
  for (int i = 0; i < rings; ++i) {
    const double r1 = a_mm * (i + 1) / rings, rm = a_mm * (i + 0.5) / rings;
    const double upto = i + 1 == rings ? 1.0 : ConeForceShareWithin(r1, a_mm);
    const double w = upto - below;
    below = upto;
    const int sectors = 4 * (i + 1);
    for (int k = 0; k < sectors; ++k) {
      const double t = 2 * M_PI * (k + 0.5) / sectors;
      deposit(rm * std::cos(t), rm * std::sin(t), w / sectors);
    }
  }
  if (!(total > 0)) return;
  std::sort(touched.begin(), touched.end());
  const double scale = force_N / total;
  for (const int cell : touched) loads->push_back({cell, scale * grid[size_t(cell)], 0, 0});
}

}  // namespace sedbridge::sensors
