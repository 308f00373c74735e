#pragma once
// display::SedField <-> lcmt_merkel_sed (channel FINGERTIP_SED).

#include "display/sed_field.h"
#include "sedbridge/lcmt_merkel_sed.hpp"

namespace sedbridge::lcm_io {

/// Sends positions (num_positions == num_vertices); max_sed_Pa = MaxFiniteSed. Values beyond
/// float range -> +-Inf, NaN stays NaN (lcm/lcm_float.h).
lcmt_merkel_sed ToLcm(const display::SedField& f);
/// A message with ids only (num_positions == 0) gives a field without positions; the mapping
/// then sees an inconsistent field (fault) unless the caller fills x/y/z from its model.
/// Mismatched counts in a hand-made message are not "repaired": the vectors keep their sizes.
display::SedField FromLcm(const lcmt_merkel_sed& m);

}  // namespace sedbridge::lcm_io
