#include "render/display_on_leader.h"

#include <stdexcept>

#include "render/pin_display_on_leader.h"

namespace sedbridge::render {

std::unique_ptr<DisplayOnLeader> MakeDisplayOnLeader(scene::FingertipCompliance& leader,
                                                     const display::DisplayDevice& device) {
  if (device.footprints.empty()) throw std::invalid_argument("display on the leader: the profile has no device model");
  switch (device.kind) {
    case display::DisplayKind::kPin:
      return std::make_unique<PinDisplayOnLeader>(leader, device);
    default:
      break;
  }
  throw std::invalid_argument(std::string("display on the leader: no mechanical load for a ") +
                              display::ToString(device.kind) + " display");
}

}  // namespace sedbridge::render
