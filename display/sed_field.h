#pragma once
// The Merkel-layer strain energy density (SED) field of one FE step: the one input the
// display stage takes from the FE side.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sedbridge::display {

/// SED at the vertices of the fingertip model's Merkel layer (epidermis-dermis interface).
/// All vectors are per vertex and must have the same length, except z_mm, which may be
/// empty when the producer does not know depth. The contents are untrusted: NaN, Inf,
/// negative or huge values and mismatched lengths are handled downstream, not assumed away.
struct SedField {
  int64_t utime = 0;              ///< time of the FE step [us]
  int64_t source_scan_utime = 0;  ///< tactile scan that drove the step [us]; 0 = none
  std::string model_id;           ///< fingertip model, e.g. "B"
  /// Vertex positions in the pad frame [mm]: x lateral, y along the finger toward the tip,
  /// z along the outward pad normal (origin on the pad surface).
  std::vector<double> x_mm, y_mm, z_mm;
  std::vector<double> sed_Pa;     ///< vertex SED [Pa] = [J/m^3]; >= 0 when healthy

  std::size_t size() const { return sed_Pa.size(); }
};

/// What is wrong with a field, counted per vertex.
struct SedFieldCheck {
  bool consistent = true;          ///< false: vector lengths disagree (field unusable)
  std::size_t non_finite_sed = 0;  ///< NaN or +-Inf SED values
  std::size_t negative_sed = 0;    ///< finite but < 0 (numerical noise; read as 0)
  std::size_t non_finite_position = 0;  ///< vertices with a NaN/Inf coordinate (ignored)

  bool healthy() const {
    return consistent && non_finite_sed == 0 && negative_sed == 0 && non_finite_position == 0;
  }
};

/// Counts the problems of `field` (O(#vertices), no allocation).
SedFieldCheck CheckSedField(const SedField& field);

/// Largest finite SED of the field [Pa]; 0 for an empty field or one with no finite value.
double MaxFiniteSed(const SedField& field);

}  // namespace sedbridge::display
