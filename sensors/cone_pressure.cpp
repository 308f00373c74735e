#include "sensors/cone_pressure.h"

#include <algorithm>
#include <cmath>

#include "sensors/grid_splat.h"

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
  GridSplat splat(origin, h, n);
  auto deposit = [&](double u, double v, double w) { splat.Deposit(x_mm + u, y_mm + v, w); };
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
  splat.Emit(force_N, loads);
}

}  // namespace sedbridge::sensors
