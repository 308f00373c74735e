#pragma once
// Bessel functions J0 and J1 by the rational approximations of Abramowitz & Stegun 9.4.1-
// 9.4.6 (absolute error below 1e-7 everywhere): the layer's Hankel transforms
// (elastic_pad_contact.cpp) need a few million of them, and std::cyl_bessel_j costs about
// ten times as much for digits a deflection table does not use.

#include <cmath>

namespace sedbridge::sensors {

inline double BesselJ0(double x) {
  x = std::abs(x);
  if (x <= 3) {
    const double y = (x / 3) * (x / 3);
    return 1 + y * (-2.2499997 + y * (1.2656208 + y * (-0.3163866 + y * (0.0444479 + y * (-0.0039444 + y * 0.0002100)))));
  }
  const double y = 3 / x;
  const double f = 0.79788456 + y * (-0.00000077 + y * (-0.00552740 + y * (-0.00009512 +
                   y * (0.00137237 + y * (-0.00072805 + y * 0.00014476)))));
  const double theta = x - 0.78539816 + y * (-0.04166397 + y * (-0.00003954 + y * (0.00262573 +
                       y * (-0.00054125 + y * (-0.00029333 + y * 0.00013558)))));
  return f * std::cos(theta) / std::sqrt(x);
}

/// J1(x) / x (finite at 0, where it is 1/2).
inline double BesselJ1OverX(double x) {
  const double ax = std::abs(x);
  if (ax <= 3) {
    const double y = (ax / 3) * (ax / 3);
    return 0.5 + y * (-0.56249985 + y * (0.21093573 + y * (-0.03954289 + y * (0.00443319 +
                 y * (-0.00031761 + y * 0.00001109)))));
  }
  const double y = 3 / ax;
  const double f = 0.79788456 + y * (0.00000156 + y * (0.01659667 + y * (0.00017105 +
                   y * (-0.00249511 + y * (0.00113653 + y * (-0.00020033))))));
  const double theta = ax - 2.35619449 + y * (0.12499612 + y * (0.00005650 + y * (-0.00637879 +
                       y * (0.00074348 + y * (0.00079824 + y * (-0.00029166))))));
  return f * std::cos(theta) / (ax * std::sqrt(ax));
}

}  // namespace sedbridge::sensors
