#pragma once
// Parameters of the follower sensor's forward model (sensors/tactile_forward_model.h): the
// `forward_model` mapping of a sensor profile, calibrated by `sedbridge fit-sensor`.

#include <array>
#include <string>

#include "common/name_value.h"

namespace sedbridge::config {
class MapReader;
}

namespace sedbridge::sensors {

/// A radial kernel A f(rho / s) / (1 + (rho/s)^2)^q.
struct RadialKernel {
  double gain = 0;      ///< A [-]
  double width_mm = 1;  ///< s
  double power = 1.5;   ///< q
};

/// Parameters of the model (sensor profile key `forward_model`, config/sensors/README.md).
struct TactileModelParams {
  double contact_modulus_kPa = 330;  ///< E* of the pad for the Hertz patches
  double pad_size_mm = 18.8;         ///< side of the square sensing surface (flat, rod length)
  RadialKernel normal;               ///< Kn: normal load -> z
  RadialKernel spread;               ///< Kr: normal load -> outward x/y
  RadialKernel shear;                ///< Kt: tangential load -> x/y along it
  RadialKernel shear_cross;          ///< Kc: tangential load -> x/y along e (e . T)
  RadialKernel shear_lift;           ///< Kl: tangential load -> z
  double grid_mm = 0.235;            ///< load grid spacing h (pitch / 20 for uskin_4x4)
  /// Smallest half-width of a rod's pressure band [mm]: the band is sqrt(b_Hertz^2 + w^2)
  /// wide with w = max(grid_mm, this), since the sensor's cover spreads a line contact over a
  /// width of its own, whatever the rod's radius. Not one of the fitted unknowns (the
  /// hold and ramp readings at known objects hardly depend on it:
  /// docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s1, "A rod's band"); `fit-sensor
  /// --rod-radii` reports the radius that best explains each rig rod's hold with it. 0: the
  /// load grid's spacing.
  double rod_min_halfwidth_mm = 0;

  /// Parameters as a flat vector (the fit's unknowns) and back; `fixed` gives the rest
  /// (grid_mm, rod_min_halfwidth_mm).
  static constexpr int kCount = 17;
  std::array<double, kCount> ToArray() const;
  static TactileModelParams FromArray(const std::array<double, kCount>& a, const TactileModelParams& fixed);
  static const std::array<const char*, kCount>& Names();

  /// The scalar keys; `kernels` ([gain, width_mm, power] each) is read by
  /// ParseTactileModelParams.
  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("contact_modulus_kPa", &contact_modulus_kPa).Positive());
    a->Visit(Field("pad_size_mm", &pad_size_mm).Positive());
    a->Visit(Field("grid_mm", &grid_mm).InRange(0.05, 2.0));
    a->Visit(Field("rod_min_halfwidth_mm", &rod_min_halfwidth_mm).InRange(0.0, 5.0));
  }
};

/// Throws std::invalid_argument unless gain is finite, width_mm > 0 and power > 0.
void CheckKernel(const RadialKernel& kernel, const char* name);

/// Parses a `forward_model` mapping:
///   contact_modulus_kPa: 330
///   pad_size_mm: 18.8
///   grid_mm: 0.235
///   rod_min_halfwidth_mm: 0.3      (optional; 0 = grid_mm)
///   kernels: {normal: [A, s_mm, q], spread: [...], shear: [...], shear_cross: [...],
///             shear_lift: [...]}
TactileModelParams ParseTactileModelParams(config::MapReader& reader);
/// The same mapping as YAML text (what fit-sensor writes), indented by `indent` spaces.
std::string TactileModelParamsYaml(const TactileModelParams& params, int indent);

}  // namespace sedbridge::sensors
