#pragma once
// Plain structs <-> generated LCM messages. LCM carries float: values beyond float range
// become +-Inf, NaN stays NaN — receivers treat fields as untrusted anyway.

#include "display/display_command.h"
#include "display/sed_field.h"
#include "sedbridge/lcmt_display_command.hpp"
#include "sedbridge/lcmt_merkel_sed.hpp"

namespace sedbridge::display {

/// double -> float without undefined behaviour: beyond float range -> +-Inf, NaN stays NaN.
float ToLcmFloat(double x);

lcmt_display_command ToLcm(const DisplayCommand& c);
DisplayCommand FromLcm(const lcmt_display_command& m);

/// Sends positions (num_positions == num_vertices); max_sed_Pa = MaxFiniteSed.
lcmt_merkel_sed ToLcm(const SedField& f);
/// A message with ids only (num_positions == 0) gives a field without positions; the mapping
/// then sees an inconsistent field (fault) unless the caller fills x/y/z from its model.
/// Mismatched counts in a hand-made message are not "repaired": the vectors keep their sizes.
SedField FromLcm(const lcmt_merkel_sed& m);

}  // namespace sedbridge::display
