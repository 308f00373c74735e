#pragma once
// Merkel-layer SED field -> requested actuator values (before the safety limiter).

#include <cstddef>
#include <vector>

#include "display/display_profile.h"
#include "display/sed_field.h"

namespace sedbridge::display {

/// Samples the SED field at each actuator site and passes it through the profile's transfer
/// function (see MappingParams). Stateless and const: safe to share between threads.
///
/// Untrusted input: a negative vertex SED is read as 0 (counted in the check). A field with
/// any NaN/Inf SED or coordinate, or whose vector lengths disagree, is rejected as a whole by
/// Map(): every request is NaN, because a non-finite value anywhere means the FE step failed
/// and its finite values cannot be trusted either. The SafetyLimiter turns NaN into 0 with the
/// fault flag, so a bad field is never silently rendered as "no touch". Huge finite SED
/// saturates.
class SedToCommandMapping {
 public:
  struct Result {
    std::vector<double> sed_at_site_Pa;  ///< sampled SED per actuator [Pa] (NaN = bad input)
    std::vector<double> requested;       ///< transfer output per actuator [display unit]
    SedFieldCheck check;                 ///< problems found in the field
  };

  /// @param[in] site_x_mm, site_y_mm  actuator sites in the pad frame [mm], same length
  /// @param[in] params                sampling + transfer; throws std::invalid_argument when a
  ///                                  parameter is out of range or calibration has the wrong length
  SedToCommandMapping(std::vector<double> site_x_mm, std::vector<double> site_y_mm,
                      MappingParams params);
  explicit SedToCommandMapping(const DisplayProfile& profile);

  /// Maps one field. O(#vertices x #actuators) (time per field: docs/performance.md,
  /// "Display mapping").
  Result Map(const SedField& field) const;

  /// Samples SED at actuator `site` [Pa] (no whole-field rejection): 0 when no usable vertex
  /// lies within the radius, NaN when a non-finite SED does; NaN-position vertices are skipped.
  double Sample(const SedField& field, std::size_t site) const;

  /// True when Sample() would read a vertex at this pad-frame position [mm] for some site
  /// (within radius_mm in x-y of it and inside the z window): the SED a producer must
  /// compute for this display; every other vertex leaves every command unchanged.
  bool Reads(double x_mm, double y_mm, double z_mm) const;

  /// Transfer function for actuator `site`: SED [Pa] -> value [unit]; NaN in -> NaN out.
  double Transfer(double sed_Pa, std::size_t site) const;

  std::size_t size() const { return site_x_mm_.size(); }
  const MappingParams& params() const { return params_; }

 private:
  std::vector<double> site_x_mm_, site_y_mm_;
  MappingParams params_;
};

}  // namespace sedbridge::display
