#include "render/display_on_leader.h"

#include <stdexcept>

#include "render/pin_display_on_leader.h"

namespace sedbridge::render {

namespace {

using Maker = std::unique_ptr<DisplayOnLeader> (*)(scene::FingertipCompliance& leader,
                                                   const display::DisplayDevice& device);

template <typename Display>
std::unique_ptr<DisplayOnLeader> Make(scene::FingertipCompliance& leader, const display::DisplayDevice& device) {
  return std::make_unique<Display>(leader, device);
}

// The one list of display kinds with a mechanical load: the factory builds from it and
// HasMechanicalLoad answers from it, so a kind added here is rendered by the bridge at once.
Maker MakerOf(display::DisplayKind kind) {
  switch (kind) {
    case display::DisplayKind::kPin:
      return &Make<PinDisplayOnLeader>;
    default:
      return nullptr;
  }
}

}  // namespace

bool HasMechanicalLoad(display::DisplayKind kind) { return MakerOf(kind) != nullptr; }

std::unique_ptr<DisplayOnLeader> MakeDisplayOnLeader(scene::FingertipCompliance& leader,
                                                     const display::DisplayDevice& device) {
  if (device.footprints.empty()) throw std::invalid_argument("display on the leader: the profile has no device model");
  if (const Maker make = MakerOf(device.kind)) return make(leader, device);
  throw std::invalid_argument(std::string("display on the leader: no mechanical load for a ") +
                              display::ToString(device.kind) + " display");
}

}  // namespace sedbridge::render
