#pragma once
// display::DisplayCommand <-> lcmt_display_command (channel DISPLAY_COMMAND).

#include <cstddef>

#include "display/display_command.h"
#include "sedbridge/lcmt_display_command.hpp"

namespace sedbridge::lcm_io {

/// Values are narrowed to float never rounding up, so a value at the hard max stays at or
/// below it; beyond float range -> +-Inf, NaN stays NaN (lcm/lcm_float.h).
lcmt_display_command ToLcm(const display::DisplayCommand& c);
display::DisplayCommand FromLcm(const lcmt_display_command& m);

/// SafeDecode + FromLcm of one DISPLAY_COMMAND payload: false when the bytes are not exactly
/// one well-formed lcmt_display_command. The display driver's decoder (display/display_driver.h).
bool DecodeDisplayCommand(const void* data, std::size_t size, display::DisplayCommand* out);

}  // namespace sedbridge::lcm_io
