#include "display/display_device.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "common/yaml_reader.h"
#include "display/display_kind_limits.h"
#include "display/display_profile.h"

namespace sedbridge::display {
namespace {

using config::MapReader;

// "0.5 mm" for messages (std::to_string prints 0.500000).
std::string Mm(double x) {
  std::ostringstream s;
  s << x << " mm";
  return s.str();
}

std::string Pair(double x, double y) {
  std::ostringstream s;
  s << "(" << x << ", " << y << ")";
  return s.str();
}

struct KindKeys {
  const char* footprint_key;           // the radius key
  const char* noun;                    // "hole", "pin"
  std::vector<const char*> required;   // every key the kind needs
  std::vector<const char*> allowed;    // every key the kind takes
};

KindKeys KeysOf(DisplayKind kind) {
  if (kind == DisplayKind::kPin)
    return {"pin_radius_mm", "pin", {"pin_radius_mm", "tip", "travel_mm", "preload_kPa", "surface_half_size_mm"},
            {"pin_radius_mm", "tip", "tip_radius_mm", "travel_mm", "preload_kPa", "surface_half_size_mm"}};
  return {"hole_radius_mm", "hole", {"hole_radius_mm", "preload_kPa", "surface_half_size_mm"},
          {"hole_radius_mm", "preload_kPa", "surface_half_size_mm"}};
}

std::string JoinKeys(const std::vector<const char*>& keys) {
  std::string s;
  for (const char* k : keys) s += (s.empty() ? "" : ", ") + std::string(k);
  return s;
}

// A key of the other kind is an error, not ignored: a pin's travel in a suction profile is
// a profile written for another device.
void CheckKeysOfKind(MapReader& d, DisplayKind kind) {
  const KindKeys k = KeysOf(kind);
  for (const char* key : {"hole_radius_mm", "pin_radius_mm", "tip", "tip_radius_mm", "travel_mm"}) {
    const bool allowed = std::any_of(k.allowed.begin(), k.allowed.end(), [&](const char* a) { return std::string(a) == key; });
    if (!allowed && d.Has(key))
      d.Fail(d.Node(key), "'" + std::string(key) + "' is no key of a " + ToString(kind) + " display's device (it takes " +
                              JoinKeys(k.allowed) + ")");
  }
  for (const char* key : k.required)
    if (!d.Has(key)) d.Fail("a " + ToString(kind) + " display's 'device' needs '" + key + "'");
}

void CheckPinKeys(MapReader& d, const DisplayProfile& p) {
  const DisplayDevice& dev = p.device;
  if (dev.tip == PinTip::kFlat && d.Has("tip_radius_mm"))
    d.Fail(d.Node("tip_radius_mm"), "'tip_radius_mm' is for a rounded tip; a flat tip has none");
  if (dev.tip == PinTip::kRounded) {
    if (!d.Has("tip_radius_mm")) d.Fail(d.Node("tip"), "a rounded tip needs 'tip_radius_mm'");
    // A spherical cap on a pin of radius a has radius >= a.
    if (dev.tip_radius_mm < dev.pin_radius_mm)
      d.Fail(d.Node("tip_radius_mm"), "'tip_radius_mm' (" + Mm(dev.tip_radius_mm) + ") must be >= 'pin_radius_mm' (" +
                                          Mm(dev.pin_radius_mm) + "): the tip is a spherical cap on the pin");
  }
  // Neither the device range nor the limiter may ask for a height the pin cannot reach.
  const double kind_max = LimitsOf(DisplayKind::kPin).max_value;
  if (dev.travel_mm > kind_max)
    d.Fail(d.Node("travel_mm"), "'travel_mm' (" + Mm(dev.travel_mm) + ") exceeds " + Mm(kind_max) +
                                    ", the most any pin display may take (config/displays/README.md)");
  if (dev.travel_mm < p.safety.max)
    d.Fail(d.Node("travel_mm"), "'travel_mm' (" + Mm(dev.travel_mm) + ") is below safety.max (" + Mm(p.safety.max) +
                                    "): the limiter would allow heights the pin cannot reach");
  if (dev.travel_mm < p.range_max)
    d.Fail(d.Node("travel_mm"), "'travel_mm' (" + Mm(dev.travel_mm) + ") is below range[1] (" + Mm(p.range_max) +
                                    "): the device would accept heights beyond its pin's stroke");
}

// Neighbouring holes (pins) must not touch: the radius is below half the smallest distance
// between two sites.
void CheckRadiusAgainstNeighbours(MapReader& d, const DisplayProfile& p) {
  const KindKeys k = KeysOf(p.kind);
  const double r = p.device.footprint_radius_mm();
  const double nearest_mm = NearestActuatorDistance_mm(p.x_mm, p.y_mm);
  if (!(r < nearest_mm / 2))
    d.Fail(d.Node(k.footprint_key), "'" + std::string(k.footprint_key) + "' (" + Mm(r) +
                                        ") must be below half the nearest actuator distance (" + Mm(nearest_mm) +
                                        " / 2): neighbouring " + k.noun + "s would overlap");
}

void CheckSurfaceCoversFootprints(MapReader& d, const DisplayProfile& p) {
  const DisplayDevice& dev = p.device;
  for (std::size_t i = 0; i < dev.footprints.size(); ++i) {
    const ActuatorFootprint& f = dev.footprints[i];
    if (std::abs(f.x_mm - dev.surface_center_mm[0]) + f.radius_mm <= dev.surface_half_size_mm[0] &&
        std::abs(f.y_mm - dev.surface_center_mm[1]) + f.radius_mm <= dev.surface_half_size_mm[1])
      continue;
    d.Fail(d.Node("surface_half_size_mm"),
           "'surface_half_size_mm' " + Pair(dev.surface_half_size_mm[0], dev.surface_half_size_mm[1]) +
               " mm does not cover actuator " + std::to_string(i) + " at " + Pair(f.x_mm, f.y_mm) + " mm with its " +
               Mm(f.radius_mm) + " " + KeysOf(p.kind).noun + " (the surface is centred on the actuators' centre " +
               Pair(dev.surface_center_mm[0], dev.surface_center_mm[1]) + " mm)");
  }
}

}  // namespace

const config::EnumNames<PinTip>& NamesOf(PinTip) {
  static const config::EnumNames<PinTip> names{{PinTip::kFlat, "flat"}, {PinTip::kRounded, "rounded"}};
  return names;
}

double NearestActuatorDistance_mm(const std::vector<double>& x_mm, const std::vector<double>& y_mm) {
  // Sweep in x order: a pair further apart in x than the best so far cannot be nearer.
  std::vector<std::size_t> order(x_mm.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return x_mm[a] < x_mm[b]; });
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < order.size(); ++i)
    for (std::size_t j = i + 1; j < order.size() && x_mm[order[j]] - x_mm[order[i]] < best; ++j)
      best = std::min(best, std::hypot(x_mm[order[j]] - x_mm[order[i]], y_mm[order[j]] - y_mm[order[i]]));
  return best;
}

void CompleteDisplayDevice(MapReader& d, DisplayProfile& p) {
  DisplayDevice& dev = p.device;
  dev.kind = p.kind;
  CheckKeysOfKind(d, p.kind);  // electrotactile was refused before its keys were read
  if (p.kind == DisplayKind::kPin) CheckPinKeys(d, p);
  CheckRadiusAgainstNeighbours(d, p);
  const auto [x_min, x_max] = std::minmax_element(p.x_mm.begin(), p.x_mm.end());
  const auto [y_min, y_max] = std::minmax_element(p.y_mm.begin(), p.y_mm.end());
  dev.surface_center_mm = {(*x_min + *x_max) / 2, (*y_min + *y_max) / 2};
  dev.footprints.clear();
  for (std::size_t i = 0; i < p.size(); ++i) dev.footprints.push_back({p.x_mm[i], p.y_mm[i], dev.footprint_radius_mm()});
  CheckSurfaceCoversFootprints(d, p);
}

std::string CheckDeviceFitsPad(const DisplayProfile& p, const PadExtent& pad) {
  const bool device = p.has_device_model();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double r = device ? p.device.footprints[i].radius_mm : 0.0;
    const double x = p.x_mm[i], y = p.y_mm[i];
    if (x - r >= pad.x_min_mm && x + r <= pad.x_max_mm && y - r >= pad.y_min_mm && y + r <= pad.y_max_mm) continue;
    std::ostringstream m;
    m << p.actuators_at.str() << ": actuator " << i << " at " << Pair(x, y) << " mm";
    if (device) m << " with its " << Mm(r) << " " << KeysOf(p.kind).noun << " (device at " << p.device_at.str() << ")";
    // The extent to 0.01 mm (a mesh's patch has many digits, none of them news).
    const auto mm = [](double v) { return std::round(v * 100) / 100; };
    m << " is not on the finger's pad, whose contact face spans x " << mm(pad.x_min_mm) << ".." << mm(pad.x_max_mm)
      << " mm, y " << mm(pad.y_min_mm) << ".." << mm(pad.y_max_mm) << " mm (pad frame)";
    return m.str();
  }
  return "";
}

std::string CheckDeviceFitsPad(const DisplayProfile& p, double pad_half_x_mm, double pad_half_y_mm) {
  return CheckDeviceFitsPad(p, PadExtent{-pad_half_x_mm, pad_half_x_mm, -pad_half_y_mm, pad_half_y_mm});
}

}  // namespace sedbridge::display
