#include "display/display_profile.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/resource_path.h"
#include "common/yaml_read_archive.h"
#include "display/display_kind_limits.h"

namespace sedbridge::display {
namespace {

using config::As;
using config::MapReader;

// Reads a number that must be finite and satisfy `ok`; fails at the value's location.
template <typename Pred>
double ReadNumber(MapReader& r, const std::string& key, Pred ok, const std::string& rule) {
  YAML::Node v = r.Node(key);
  const double x = As<double>(v, r.file(), key);
  if (!std::isfinite(x) || !ok(x)) r.Fail(v, "'" + key + "' " + rule);
  return x;
}

template <typename Pred>
double ReadOptionalNumber(MapReader& r, const std::string& key, double fallback, Pred ok,
                          const std::string& rule) {
  if (!r.Has(key)) {
    r.Optional<double>(key, fallback);  // marks the key as known
    return fallback;
  }
  return ReadNumber(r, key, ok, rule);
}

// A sequence of exactly `n` finite numbers.
std::vector<double> ReadVector(MapReader& r, const std::string& key, std::size_t n) {
  YAML::Node v = r.Node(key);
  if (!v.IsSequence() || v.size() != n)
    r.Fail(v, "'" + key + "' must be a list of " + std::to_string(n) + " numbers");
  std::vector<double> out;
  for (const auto& e : v) {
    const double x = As<double>(e, r.file(), key);
    if (!std::isfinite(x)) r.Fail(e, "'" + key + "' entries must be finite");
    out.push_back(x);
  }
  return out;
}

void ReadActuators(MapReader& r, DisplayProfile& p) {
  const bool has_grid = r.Has("grid"), has_list = r.Has("positions_mm");
  if (has_grid == has_list) r.Fail("'actuators' needs exactly one of 'grid' or 'positions_mm'");
  if (has_grid) {
    MapReader g = r.Child("grid");
    YAML::Node rows_node = g.Node("rows"), cols_node = g.Node("cols");
    const int rows = As<int>(rows_node, g.file(), "rows");
    const int cols = As<int>(cols_node, g.file(), "cols");
    if (rows < 1 || rows > 256) g.Fail(rows_node, "'rows' must be in [1, 256]");
    if (cols < 1 || cols > 256) g.Fail(cols_node, "'cols' must be in [1, 256]");
    const std::vector<double> pitch = ReadVector(g, "pitch_mm", 2);
    if (pitch[0] <= 0 || pitch[1] <= 0) g.Fail(g.Node("pitch_mm"), "'pitch_mm' must be > 0");
    const std::vector<double> center = ReadVector(g, "center_mm", 2);
    g.Finish();
    // Row-major, row 0 nearest the tip (largest y), column 0 at the smallest x: the order a
    // person reads the array looking at the pad with the tip up.
    for (int row = 0; row < rows; ++row) {
      for (int col = 0; col < cols; ++col) {
        p.x_mm.push_back(center[0] + (col - (cols - 1) / 2.0) * pitch[0]);
        p.y_mm.push_back(center[1] + ((rows - 1) / 2.0 - row) * pitch[1]);
      }
    }
  } else {
    YAML::Node list = r.Node("positions_mm");
    if (!list.IsSequence() || list.size() == 0)
      r.Fail(list, "'positions_mm' must be a non-empty list of [x, y] pairs");
    for (const auto& e : list) {
      if (!e.IsSequence() || e.size() != 2) r.Fail(e, "each position must be [x_mm, y_mm]");
      const double x = As<double>(e[0], r.file(), "positions_mm");
      const double y = As<double>(e[1], r.file(), "positions_mm");
      if (!std::isfinite(x) || !std::isfinite(y)) r.Fail(e, "positions must be finite");
      p.x_mm.push_back(x);
      p.y_mm.push_back(y);
    }
  }
  r.Finish();
}

// "20 kPa" for messages (std::to_string prints 20.000000).
std::string WithUnit(double x, const std::string& unit) {
  std::ostringstream s;
  s << x << " " << unit;
  return s.str();
}

void ReadSafety(MapReader& r, DisplayProfile& p) {
  auto positive = [](double x) { return x > 0; };
  const DisplayKindLimits kind = LimitsOf(p.kind);
  p.safety.max = ReadNumber(r, "max", positive, "must be > 0");
  if (p.safety.max > p.range_max)
    r.Fail(r.Node("max"), "'max' (" + WithUnit(p.safety.max, p.unit) +
                              ") exceeds the device range maximum " + WithUnit(p.range_max, p.unit));
  // The device renders nothing between 0 and range[0]; a max at or below it would leave the
  // display unable to turn on, which is a config mistake, not a safe setting.
  if (p.safety.max <= p.range_min)
    r.Fail(r.Node("max"), "'max' (" + WithUnit(p.safety.max, p.unit) +
                              ") must be above the device range minimum " + WithUnit(p.range_min, p.unit));
  p.safety.max_per_actuator.assign(p.size(), p.safety.max);
  if (r.Has("max_per_actuator")) {
    std::vector<double> per = ReadVector(r, "max_per_actuator", p.size());
    for (std::size_t i = 0; i < per.size(); ++i) {
      if (per[i] < 0 || per[i] > p.safety.max)
        r.Fail(r.Node("max_per_actuator")[i], "'max_per_actuator' entries must be in [0, max]");
      p.safety.max_per_actuator[i] = per[i];
    }
  }
  p.safety.slew_rate_per_s = ReadNumber(
      r, "slew_rate_per_s", [&](double x) { return x > 0 && x <= kind.max_slew_per_s; },
      "must be in (0, " + WithUnit(kind.max_slew_per_s, p.unit) + "/s] for a " + ToString(p.kind) +
          " display (full scale in no less than 0.1 s)");
  p.safety.watchdog_timeout_s = ReadNumber(
      r, "watchdog_timeout_s", [](double x) { return x > 0 && x <= kMaxWatchdogTimeout_s; },
      "must be in (0, " + std::to_string(kMaxWatchdogTimeout_s) + "] s");
  r.Finish();
}

void ReadMapping(MapReader& r, DisplayProfile& p) {
  MappingParams& m = p.mapping;
  config::YamlReadArchive archive(&r);
  archive.Visit(config::Field("sampling", &m.sampling).Required());
  auto positive = [](double x) { return x > 0; };
  m.radius_mm = ReadNumber(r, "radius_mm", positive, "must be > 0");
  if (r.Has("z_window_mm")) {
    std::vector<double> z = ReadVector(r, "z_window_mm", 2);
    if (!(z[0] < z[1])) r.Fail(r.Node("z_window_mm"), "'z_window_mm' must be [min, max], min < max");
    m.z_min_mm = z[0];
    m.z_max_mm = z[1];
  }
  m.threshold_Pa = ReadOptionalNumber(r, "threshold_Pa", 0.0, [](double x) { return x >= 0; },
                                      "must be >= 0");
  m.reference_Pa = ReadNumber(r, "reference_Pa", positive, "must be > 0");
  m.gain = ReadNumber(r, "gain", positive, "must be > 0");
  m.exponent = ReadOptionalNumber(r, "exponent", 1.0,
                                  [](double x) { return x >= 0.1 && x <= 10; },
                                  "must be in [0.1, 10]");
  const double kind_max = LimitsOf(p.kind).max_value;
  m.saturation = ReadOptionalNumber(r, "saturation", p.safety.max,
                                    [&](double x) { return x > 0 && x <= kind_max; },
                                    "must be in (0, " + WithUnit(kind_max, p.unit) + "]");
  if (r.Has("calibration")) {
    MapReader c = r.Child("calibration");
    if (c.Has("gain")) {
      m.calibration_gain = ReadVector(c, "gain", p.size());
      for (std::size_t i = 0; i < p.size(); ++i)
        if (m.calibration_gain[i] <= 0 || m.calibration_gain[i] > kMaxCalibrationGain)
          c.Fail(c.Node("gain")[i], "calibration gains must be in (0, " + WithUnit(kMaxCalibrationGain, "]"));
    }
    if (c.Has("offset")) {
      m.calibration_offset = ReadVector(c, "offset", p.size());
      for (std::size_t i = 0; i < p.size(); ++i)
        if (std::abs(m.calibration_offset[i]) > kind_max)
          c.Fail(c.Node("offset")[i], "calibration offsets must be within +-" + WithUnit(kind_max, p.unit));
    }
    c.Finish();
  }
  r.Finish();
}

}  // namespace

const config::EnumNames<DisplayKind>& NamesOf(DisplayKind) {
  static const config::EnumNames<DisplayKind> names{
      {DisplayKind::kSuction, "suction"}, {DisplayKind::kPin, "pin"}, {DisplayKind::kElectrotactile, "electrotactile"}};
  return names;
}

const config::EnumNames<SamplingMethod>& NamesOf(SamplingMethod) {
  static const config::EnumNames<SamplingMethod> names{{SamplingMethod::kInterpolate, "interpolate"},
                                                       {SamplingMethod::kMaxWithinRadius, "max_within_radius"},
                                                       {SamplingMethod::kMeanWithinRadius, "mean_within_radius"}};
  return names;
}

std::string ToString(DisplayKind kind) { return config::NameOf(kind); }

std::string UnitOf(DisplayKind kind) {
  switch (kind) {
    case DisplayKind::kSuction: return "kPa";
    case DisplayKind::kPin: return "mm";
    case DisplayKind::kElectrotactile: return "mA";
  }
  return "?";
}

namespace {

DisplayProfile Parse(const config::YamlDocument& doc) {
  MapReader r(doc.root, doc.file);
  DisplayProfile p;
  p.file = doc.file;
  p.name = r.Required<std::string>("name");
  p.description = r.Optional<std::string>("description", "");
  config::YamlReadArchive archive(&r);
  archive.Visit(config::Field("kind", &p.kind).Required());
  const std::string kind = ToString(p.kind);
  YAML::Node unit_node = r.Node("unit");
  p.unit = As<std::string>(unit_node, r.file(), "unit");
  if (p.unit != UnitOf(p.kind))
    r.Fail(unit_node, "a " + kind + " display takes '" + UnitOf(p.kind) + "' (got '" + p.unit + "')");

  MapReader actuators = r.Child("actuators");
  ReadActuators(actuators, p);

  std::vector<double> range = ReadVector(r, "range", 2);
  if (!(range[0] >= 0 && range[0] < range[1]))
    r.Fail(r.Node("range"), "'range' must be [min, max] with 0 <= min < max");
  const double kind_max = LimitsOf(p.kind).max_value;
  if (range[1] > kind_max)
    r.Fail(r.Node("range"), "'range' maximum " + WithUnit(range[1], p.unit) + " exceeds " + WithUnit(kind_max, p.unit) +
                                ", the most any " + ToString(p.kind) + " display may take (config/displays/README.md)");
  p.range_min = range[0];
  p.range_max = range[1];

  MapReader safety = r.Child("safety");
  ReadSafety(safety, p);
  MapReader mapping = r.Child("mapping");
  ReadMapping(mapping, p);
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
