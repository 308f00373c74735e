#pragma once
// The leader's pad as a display meets it: the x-y extent (pad frame) of the skin that can
// touch anything in the leader's FE model, its candidate contact patch (skin facing the pad
// within FingertipComplianceOptions::max_depth_mm of its apex). An actuator beyond it can
// touch no contact point: a display whose footprints leave it is refused, naming the
// profile's `actuators` key (display::CheckDeviceFitsPad), before any precompute.

#include <stdexcept>
#include <string>

#include "display/display_device.h"
#include "display/display_profile.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::render {

/// A display that does not fit the leader's pad; what() starts with the profile's
/// file:line:column. An std::invalid_argument: the display, not a solve, is wrong.
class DisplayDoesNotFitPad : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The x-y extent of `leader`'s candidate contact nodes at rest, pad frame [mm].
display::PadExtent LeaderPadExtent(const scene::FingertipCompliance& leader);

/// Throws DisplayDoesNotFitPad when a footprint of `profile` (a site, without a device
/// model) leaves LeaderPadExtent(leader); the message names the model.
void CheckDisplayFitsLeaderPad(const display::DisplayProfile& profile, const scene::FingertipCompliance& leader);

}  // namespace sedbridge::render
