#pragma once
// The device model of a display: what each actuator physically is where it meets the
// leader's finger pad — a suction hole or a pin of a given radius in a rigid surface that
// the pad rests on with a preload. The inverse renderer turns it into a load on the leader's
// FE model (what each actuator does to the finger); the curve renderer does not use it.
// Electrotactile displays have none: no mechanical load, their rendering is against the SA1
// rate estimate. Keys `device.*` of a display profile (config/displays/README.md).

#include <array>
#include <string>
#include <vector>

#include "common/enum_names.h"
#include "common/name_value.h"
#include "display/display_kind.h"

namespace sedbridge::config {
class MapReader;
}

namespace sedbridge::display {

struct DisplayProfile;

enum class PinTip {
  kFlat,     ///< flat end face of radius pin_radius_mm
  kRounded,  ///< spherical cap of radius tip_radius_mm (>= pin_radius_mm) on the pin
};
/// "flat", "rounded" (key device.tip).
const config::EnumNames<PinTip>& NamesOf(PinTip);

/// Largest `device.preload_kPa` [kPa]: 10 N on 1 cm², several times a firm touch; beyond it
/// the pad is no longer resting on the display but pressing into it.
inline constexpr double kMaxPreload_kPa = 100.0;
/// Largest `device.surface_half_size_mm` entry [mm]: a 10 cm plate, far wider than a finger.
inline constexpr double kMaxSurfaceHalfSize_mm = 50.0;

/// Where one actuator meets the pad: a disc (suction hole or pin cross-section), pad frame.
struct ActuatorFootprint {
  double x_mm = 0, y_mm = 0;  ///< centre [mm]
  double radius_mm = 0;       ///< hole or pin radius [mm]
};

/// A display's device model (key `device`); only suction and pin displays have one.
struct DisplayDevice {
  DisplayKind kind = DisplayKind::kSuction;  ///< the profile's kind: suction or pin
  /// One per actuator, in command order (the profile's sites with the hole or pin radius).
  std::vector<ActuatorFootprint> footprints;
  double hole_radius_mm = 0;   ///< suction: radius of each hole [mm]; 0 for pins
  double pin_radius_mm = 0;    ///< pin: radius of each pin [mm]; 0 for suction
  PinTip tip = PinTip::kFlat;  ///< pin: tip shape
  double tip_radius_mm = 0;    ///< rounded pin: radius of the tip's spherical cap [mm]; else 0
  double travel_mm = 0;        ///< pin: stroke above the rest plane [mm]; 0 for suction
  /// The pad's contact pressure on the display surface with every actuator off [kPa].
  double preload_kPa = 0;
  /// The rigid surface the pad rests on (suction: holes in it; pins: rise through it),
  /// half sizes [x, y] [mm], centred on surface_center_mm.
  std::array<double, 2> surface_half_size_mm{};
  /// Centre of the actuators' bounding box (a grid's center_mm), pad frame [mm].
  std::array<double, 2> surface_center_mm{};

  /// hole_radius_mm or pin_radius_mm, whichever the kind has [mm].
  double footprint_radius_mm() const { return kind == DisplayKind::kPin ? pin_radius_mm : hole_radius_mm; }

  /// Keys of `device`. Which keys a kind needs or refuses, and the bounds that span keys
  /// (radius vs pitch, surface vs actuators, travel vs range) are checked by
  /// CompleteDisplayDevice.
  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("hole_radius_mm", &hole_radius_mm).Positive());
    a->Visit(Field("pin_radius_mm", &pin_radius_mm).Positive());
    a->Visit(Field("tip", &tip));
    a->Visit(Field("tip_radius_mm", &tip_radius_mm).Positive());
    a->Visit(Field("travel_mm", &travel_mm).Positive());
    a->Visit(Field("preload_kPa", &preload_kPa).InRange(0, kMaxPreload_kPa));
    a->Visit(Field("surface_half_size_mm", &surface_half_size_mm).Within({0, kMaxSurfaceHalfSize_mm, true, false}));
  }
};

/// Finishes `p.device` after its keys were read (DisplayProfile::Serialize) and the
/// actuators placed: checks that the kind has a device model and every key it needs and
/// none of another kind's, the radius against half the nearest actuator distance, the
/// surface against every footprint, a pin's travel against range[1] and safety.max; then
/// fills kind, footprints and surface_center_mm. `device` reads the profile's `device`
/// mapping. Throws config::ConfigError at the offending key.
void CompleteDisplayDevice(config::MapReader& device, DisplayProfile& p);

/// Smallest distance between two actuator sites [mm]; infinity for a single site.
double NearestActuatorDistance_mm(const std::vector<double>& x_mm, const std::vector<double>& y_mm);

/// The part of the leader's pad a display can touch: the x-y extent of the skin that can
/// make contact, pad frame [mm] (render::LeaderPadExtent reads it from the leader's FE model:
/// its candidate contact patch). Not symmetric: the pad reaches further toward the
/// finger's base (-y) than toward its tip.
struct PadExtent {
  double x_min_mm = 0, x_max_mm = 0;
  double y_min_mm = 0, y_max_mm = 0;
};

/// Whether the display's actuators lie on the leader's pad: each footprint whole within
/// `pad` (a profile without a device model: each site). "" when they do, else a message
/// starting with the `actuators` key's file:line:column (and naming `device`'s).
std::string CheckDeviceFitsPad(const DisplayProfile& p, const PadExtent& pad);
/// The same on a pad spanning [-pad_half_x_mm, pad_half_x_mm] x [-pad_half_y_mm, pad_half_y_mm].
std::string CheckDeviceFitsPad(const DisplayProfile& p, double pad_half_x_mm, double pad_half_y_mm);

}  // namespace sedbridge::display
