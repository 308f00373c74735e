#pragma once
// sensors::Scan -> lcmt_tactile_scan (channel TACTILE_SCAN).

#include <string>

#include "sedbridge/lcmt_tactile_scan.hpp"
#include "sensors/scan.h"

namespace sedbridge::lcm_io {

/// One raw value per taxel (the normal axis of a three-axis sensor); pressure in kPa; shear
/// in kPa for a three-axis sensor (num_shear = num_taxels), none otherwise;
/// `sequence` is the sensor's own counter when it has one, else the assembler's.
/// @param[in] sensor_id  the sensor profile's name, e.g. "uskin_4x4"
lcmt_tactile_scan ToLcm(const sensors::Scan& s, const std::string& sensor_id);

}  // namespace sedbridge::lcm_io
