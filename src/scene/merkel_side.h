#pragma once
// Which side of the epidermis–dermis interface a Merkel vertex's SED is averaged over
// (scene key `outputs.merkel_side`). The SED jumps across the interface with the stiffness,
// so the two-sided mean depends on how many tets of each side meet at a vertex; the dermis
// side is the value that converged under mesh refinement in the reference
// (docs/validation.md, "At what scale does the reference converge?").

#include "common/enum_names.h"

namespace sedbridge::scene {

enum class MerkelSide { kBoth, kEpidermis, kDermis };

/// "both", "epidermis", "dermis" (the tissue names of the model's materials).
inline const config::EnumNames<MerkelSide>& NamesOf(MerkelSide) {
  static const config::EnumNames<MerkelSide> names{
      {MerkelSide::kBoth, "both"}, {MerkelSide::kEpidermis, "epidermis"}, {MerkelSide::kDermis, "dermis"}};
  return names;
}

}  // namespace sedbridge::scene
