#include "display/display_profile.h"

#include <cmath>
#include <sstream>

#include "common/resource_path.h"
#include "common/yaml_read_archive.h"
#include "display/display_kind_limits.h"

namespace sedbridge::display {
namespace {

using config::Field;
using config::MapReader;

/// The keys of `actuators.grid`.
struct ActuatorGrid {
  int rows = 0;  ///< along y
  int cols = 0;  ///< along x
  std::array<double, 2> pitch_mm{};
  std::array<double, 2> center_mm{};

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(Field("rows", &rows).Required().InRange(1, 256));
    a->Visit(Field("cols", &cols).Required().InRange(1, 256));
    a->Visit(Field("pitch_mm", &pitch_mm).Required().Positive());
    a->Visit(Field("center_mm", &center_mm).Required());
  }
};

// Row-major, row 0 nearest the tip (largest y), column 0 at the smallest x: the order a
// person reads the array looking at the pad with the tip up.
void ReadActuatorGrid(MapReader& actuators, DisplayProfile& p) {
  MapReader g = actuators.Child("grid");
  ActuatorGrid grid;
  config::ReadYaml(g, &grid);
  for (int row = 0; row < grid.rows; ++row) {
    for (int col = 0; col < grid.cols; ++col) {
      p.x_mm.push_back(grid.center_mm[0] + (col - (grid.cols - 1) / 2.0) * grid.pitch_mm[0]);
      p.y_mm.push_back(grid.center_mm[1] + ((grid.rows - 1) / 2.0 - row) * grid.pitch_mm[1]);
    }
  }
}

void ReadActuatorList(MapReader& actuators, DisplayProfile& p) {
  std::vector<std::array<double, 2>> sites_mm;
  config::YamlReadArchive archive(&actuators);
  archive.Visit(Field("positions_mm", &sites_mm));
  if (sites_mm.empty()) actuators.Fail(actuators.Node("positions_mm"), "'positions_mm' must be a non-empty list of [x, y] pairs");
  for (const auto& [x, y] : sites_mm) {
    p.x_mm.push_back(x);
    p.y_mm.push_back(y);
  }
}

void ReadActuators(MapReader& actuators, DisplayProfile& p) {
  if (actuators.Has("grid") == actuators.Has("positions_mm"))
    actuators.Fail("'actuators' needs exactly one of 'grid' or 'positions_mm'");
  if (actuators.Has("grid")) {
    ReadActuatorGrid(actuators, p);
  } else {
    ReadActuatorList(actuators, p);
  }
}

// "20 kPa" for messages (std::to_string prints 20.000000).
std::string WithUnit(double x, const std::string& unit) {
  std::ostringstream s;
  s << x << " " << unit;
  return s.str();
}

// A list key given in the file must have one entry per actuator.
void CheckPerActuator(MapReader& r, const char* key, const std::vector<double>& values, std::size_t actuators) {
  if (r.Has(key) && values.size() != actuators)
    r.Fail(r.Node(key), "'" + std::string(key) + "' must be a list of " + std::to_string(actuators) + " numbers");
}

void CheckUnitAndRange(MapReader& r, const DisplayProfile& p) {
  if (p.unit != UnitOf(p.kind))
    r.Fail(r.Node("unit"), "a " + ToString(p.kind) + " display takes '" + UnitOf(p.kind) + "' (got '" + p.unit + "')");
  if (!(p.range_min < p.range_max)) r.Fail(r.Node("range"), "'range' must be [min, max] with 0 <= min < max");
  const double kind_max = LimitsOf(p.kind).max_value;
  if (p.range_max > kind_max)
    r.Fail(r.Node("range"), "'range' maximum " + WithUnit(p.range_max, p.unit) + " exceeds " + WithUnit(kind_max, p.unit) +
                                ", the most any " + ToString(p.kind) + " display may take (config/displays/README.md)");
}

void CheckSafety(MapReader& r, DisplayProfile& p) {
  SafetyParams& safety = p.safety;
  if (safety.max > p.range_max)
    r.Fail(r.Node("max"), "'max' (" + WithUnit(safety.max, p.unit) + ") exceeds the device range maximum " +
                              WithUnit(p.range_max, p.unit));
  // The device renders nothing between 0 and range[0]; a max at or below it would leave the
  // display unable to turn on, which is a config mistake, not a safe setting.
  if (safety.max <= p.range_min)
    r.Fail(r.Node("max"), "'max' (" + WithUnit(safety.max, p.unit) + ") must be above the device range minimum " +
                              WithUnit(p.range_min, p.unit));
  CheckPerActuator(r, "max_per_actuator", safety.max_per_actuator, p.size());
  if (!r.Has("max_per_actuator")) safety.max_per_actuator.assign(p.size(), safety.max);
  for (std::size_t i = 0; i < safety.max_per_actuator.size(); ++i)
    if (safety.max_per_actuator[i] > safety.max)
      r.Fail(r.Node("max_per_actuator")[i], "'max_per_actuator' entries must be in [0, max]");
  const double max_slew_per_s = LimitsOf(p.kind).max_slew_per_s;
  if (safety.slew_rate_per_s > max_slew_per_s)
    r.Fail(r.Node("slew_rate_per_s"), "'slew_rate_per_s' must be in (0, " + WithUnit(max_slew_per_s, p.unit) +
                                          "/s] for a " + ToString(p.kind) + " display (full scale in no less than 0.1 s)");
}

void CheckMapping(MapReader& r, const DisplayProfile& p) {
  const MappingParams& m = p.mapping;
  if (!(m.z_min_mm < m.z_max_mm)) r.Fail(r.Node("z_window_mm"), "'z_window_mm' must be [min, max], min < max");
  const double kind_max = LimitsOf(p.kind).max_value;
  if (m.saturation > kind_max)
    r.Fail(r.Node("saturation"), "'saturation' must be in (0, " + WithUnit(kind_max, p.unit) + "]");
  if (!r.Has("calibration")) return;
  MapReader c = r.Child("calibration");
  CheckPerActuator(c, "gain", m.calibration_gain, p.size());
  CheckPerActuator(c, "offset", m.calibration_offset, p.size());
  for (std::size_t i = 0; i < m.calibration_offset.size(); ++i)
    if (std::abs(m.calibration_offset[i]) > kind_max)
      c.Fail(c.Node("offset")[i], "calibration offsets must be within +-" + WithUnit(kind_max, p.unit));
}

}  // namespace

const config::EnumNames<SamplingMethod>& NamesOf(SamplingMethod) {
  static const config::EnumNames<SamplingMethod> names{{SamplingMethod::kInterpolate, "interpolate"},
                                                       {SamplingMethod::kMaxWithinRadius, "max_within_radius"},
                                                       {SamplingMethod::kMeanWithinRadius, "mean_within_radius"}};
  return names;
}

namespace {

// The node of `key` itself (not its value) in `map`: where a message about the whole block
// points. Null when absent.
YAML::Node KeyNode(const YAML::Node& map, const std::string& key) {
  for (auto it = map.begin(); it != map.end(); ++it)
    if (it->first.IsScalar() && it->first.Scalar() == key) return it->first;
  return YAML::Node();
}

// Checked before the keys inside `device` are read, so that the message gives the reason
// (the kind) rather than the first key it does not know.
void RefuseDeviceOnElectrotactile(const MapReader& r) {
  if (!r.Has("device") || !r.Has("kind")) return;
  const YAML::Node kind = r.node()["kind"];
  if (!kind.IsScalar() || kind.Scalar() != config::NameOf(DisplayKind::kElectrotactile)) return;
  r.Fail(KeyNode(r.node(), "device"),
         "electrotactile has no mechanical load: its rendering is against the SA1 rate estimate; remove 'device'");
}

DisplayProfile Parse(const config::YamlDocument& doc) {
  MapReader r(doc.root, doc.file);
  DisplayProfile p;
  p.file = doc.file;
  RefuseDeviceOnElectrotactile(r);
  config::YamlReadArchive archive(&r);
  p.Serialize(&archive);
  CheckUnitAndRange(r, p);
  MapReader actuators = r.Child("actuators");
  ReadActuators(actuators, p);
  p.actuators_at = config::LocationOf(KeyNode(doc.root, "actuators"), doc.file);
  MapReader safety = r.Child("safety");
  CheckSafety(safety, p);
  if (r.Has("device")) {
    p.device_at = config::LocationOf(KeyNode(doc.root, "device"), doc.file);
    MapReader device = r.Child("device");
    CompleteDisplayDevice(device, p);
  }
  MapReader mapping = r.Child("mapping");
  CheckMapping(mapping, p);
  r.Finish();
  return p;
}

}  // namespace

DisplayProfile ParseDisplayProfile(const std::string& yaml_text, const std::string& file) {
  return Parse(config::LoadYamlString(yaml_text, file));
}

std::string ResolveDisplayProfilePath(const std::string& name_or_path) {
  return config::ResolveNameOrPath(name_or_path, "config/displays");
}

DisplayProfile LoadDisplayProfile(const std::string& path) {
  return Parse(config::LoadYamlFile(config::ResolveResource(path)));
}

DisplayProfile LoadNamedDisplayProfile(const std::string& name_or_path) {
  return LoadDisplayProfile(ResolveDisplayProfilePath(name_or_path));
}

}  // namespace sedbridge::display
