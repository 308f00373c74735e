#pragma once
// Several sensors on one frame source (a hand: `candump -l any` of can0 and can1, or several
// SocketCAN buses): which sensor's assembler each frame is for, by its interface and CAN id.
// A frame no sensor claims is counted per interface and goes nowhere; an error frame (the
// controller's state: error-passive, bus-off) goes to every sensor on its interface.

#include <cstdint>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "sensors/can_frame.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::sensors {

class FrameRouter {
 public:
  /// Sensor `index` takes the frames of `profile`'s ids on `interface`. Throws
  /// std::invalid_argument when one of those ids is already claimed on that interface
  /// (naming both sensors by `name`).
  void Claim(int index, const std::string& name, const std::string& interface, const SensorProfile& profile);

  /// The sensors `frame` is for: one, every sensor on its interface (error frames), or none
  /// (then counted in unclaimed()). Valid until the next call.
  const std::vector<int>& Route(const Frame& frame);

  /// Frames no sensor claimed, per interface name (at most kMaxInterfaces names; later ones
  /// are counted under "other").
  const std::map<std::string, int64_t>& unclaimed() const { return unclaimed_; }
  int64_t unclaimed_total() const;

  static constexpr size_t kMaxInterfaces = 64;

 private:
  // (interface, extended, id) -> sensor index
  std::map<std::tuple<std::string, bool, uint32_t>, int> by_id_;
  std::map<std::tuple<std::string, bool, uint32_t>, std::string> names_;
  std::map<std::string, std::vector<int>> by_interface_;
  std::map<std::string, int64_t> unclaimed_;
  std::vector<int> routed_;
};

}  // namespace sedbridge::sensors
