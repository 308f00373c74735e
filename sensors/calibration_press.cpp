#include "sensors/calibration_press.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "common/yaml_read_archive.h"
#include "sensors/candump_log.h"
#include "sensors/scan_assembler.h"

namespace sedbridge::sensors {

double PressProtocol::LoadFraction(double t) const {
  if (t < unloaded_s) return 0;
  t -= unloaded_s;
  if (t < ramp_s) return t / ramp_s;
  t -= ramp_s;
  if (t < hold_s) return 1;
  t -= hold_s;
  if (t < release_s) return 1 - t / release_s;
  return 0;
}

double PressProtocol::FromRigTime_s(double t_rig_s) const {
  const PressProtocol rig;
  if (unloaded_s == rig.unloaded_s && ramp_s == rig.ramp_s) return t_rig_s;  // to the bit
  return unloaded_s + (t_rig_s - rig.unloaded_s) * (ramp_s / rig.ramp_s);
}

ContactPrimitive CalibrationPress::ObjectAt(double t) const {
  ContactPrimitive c = object;
  const double f = protocol.LoadFraction(t);
  c.normal_force_N *= f;
  c.shear_x_N *= f;
  c.shear_y_N *= f;
  return c;
}

Eigen::VectorXd CalibrationPress::MeanReadings(double t0, double t1) const {
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(readings_N.empty() ? 0 : readings_N[0].size());
  int n = 0;
  for (size_t i = 0; i < t_s.size(); ++i)
    if (t_s[i] >= t0 && t_s[i] <= t1) {
      sum += readings_N[i];
      ++n;
    }
  if (n == 0) throw std::runtime_error(name + ": no scan between " + std::to_string(t0) + " and " + std::to_string(t1) + " s");
  return sum / n;
}

Eigen::VectorXd ScanReadings_N(const Scan& scan, const SensorProfile& profile) {
  const int n = scan.num_taxels;
  Eigen::VectorXd r = Eigen::VectorXd::Zero(3 * n);
  const double area_m2 = profile.taxel_area_mm2() * 1e-6;
  for (int k = 0; k < n; ++k) {
    if (!scan.valid[k]) continue;
    if (scan.num_axes == 3) {
      r[3 * k] = scan.shear_x_Pa[k] * area_m2;
      r[3 * k + 1] = scan.shear_y_Pa[k] * area_m2;
    }
    r[3 * k + 2] = scan.pressure_Pa[k] * area_m2;
  }
  return r;
}

double NewtonsPerCount(const SensorProfile& profile, int taxel, int axis) {
  const Calibration& cal = profile.calibration;
  double n = std::abs(cal.scale_per_count[static_cast<size_t>(axis)]);
  if (cal.unit != CalibrationUnit::kNewton)
    n *= profile.taxel_area_mm2() * 1e-6 * (cal.unit == CalibrationUnit::kKiloPascal ? 1e3 : 1.0);
  return n * (cal.taxel_gain.empty() ? 1.0 : cal.taxel_gain[static_cast<size_t>(taxel)]);
}

const config::EnumNames<PressShape>& NamesOf(PressShape) {
  static const config::EnumNames<PressShape> names{{PressShape::kSphere, "sphere"},
                                                   {PressShape::kCylinder, "cylinder"},
                                                   {PressShape::kFlat, "flat"},
                                                   {PressShape::kPunch, "punch"},
                                                   {PressShape::kPair, "pair"}};
  return names;
}

std::vector<CalibrationPress> PrimitivePresses(std::vector<CalibrationPress> presses) {
  presses.erase(std::remove_if(presses.begin(), presses.end(), [](const CalibrationPress& p) { return !p.is_primitive(); }),
                presses.end());
  return presses;
}

namespace {

using config::Field;

/// `object` of one case in cases.json: the object at the peak force (a pair's `objects`:
/// each as this, without traction or a pair of their own).
struct PressObjectKeys {
  PressShape shape = PressShape::kSphere;
  std::optional<std::array<double, 2>> position_mm;  ///< required but for a pair
  std::optional<double> radius_mm;  ///< > 0, required for a sphere or a cylinder
  double yaw_deg = 0;
  std::optional<double> length_mm;  ///< a finite rod's (> 0); a cylinder's only
  std::optional<std::array<double, 2>> half_size_mm;  ///< a punch's, both > 0
  std::vector<PressObjectKeys> objects;  ///< a pair's
  std::vector<double> split;             ///< a pair's: each object's share of the force
  std::array<double, 2> traction{0, 0};  ///< tangential force / normal force

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(Field("shape", &shape).Required());
    a->Visit(Field("position_mm", &position_mm));
    a->Visit(Field("radius_mm", &radius_mm));
    a->Visit(Field("yaw_deg", &yaw_deg));
    a->Visit(Field("length_mm", &length_mm).Unit("mm").Positive());
    a->Visit(Field("half_size_mm", &half_size_mm).Unit("mm").Positive());
    a->Visit(Field("objects", &objects));
    a->Visit(Field("split", &split).Within({0, 1, true, false}));
    a->Visit(Field("traction", &traction));
  }
};

/// One entry of `cases`.
struct PressCaseKeys {
  std::string log;  ///< relative to cases.json
  double force_N = 0;
  PressObjectKeys object;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(Field("log", &log).Required());
    a->Visit(Field("force_N", &force_N).Required().Unit("N").Within({0, 1e3, true, false}));
    a->Visit(Field("object", &object).Required());
  }
};

struct CasesFile {
  std::vector<PressCaseKeys> cases;
  PressProtocol protocol;  ///< every press's; keys left out keep the rig's

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(Field("cases", &cases).Required());
    a->Visit(Field("protocol", &protocol));
  }
};

// The keys a shape needs and the keys only other shapes have, checked where they stand: the
// archive knows each key's type and range, not which shape it belongs to. `in_pair`: one of
// a pair's objects (no pair and no traction of its own).
void CheckObject(const PressObjectKeys& object, const YAML::Node& node, const std::string& file, bool in_pair) {
  config::MapReader reader(node, file);
  const std::string shape = config::NameOf(object.shape);
  auto refuse = [&](const char* key, const std::string& why) {
    if (reader.Has(key)) reader.Fail(reader.Node(key), "'" + std::string(key) + "' " + why);
  };
  if (in_pair && object.shape == PressShape::kPair) reader.Fail(reader.Node("shape"), "a pair's objects cannot be pairs");
  if (in_pair) refuse("traction", "is the pair's, not one of its objects'");
  // A flat's radius is never used, so only a sphere or cylinder needs one.
  const bool rounded = object.shape == PressShape::kSphere || object.shape == PressShape::kCylinder;
  if (rounded && !(object.radius_mm.value_or(-1) > 0))
    reader.Fail("'radius_mm' (> 0) is required for a " + shape);
  if (object.shape == PressShape::kPunch || object.shape == PressShape::kPair)
    refuse("radius_mm", "is a sphere's or a cylinder's, not a " + shape + "'s");
  if (object.shape != PressShape::kCylinder) refuse("length_mm", "is a cylinder's (a finite rod), not a " + shape + "'s");
  if (object.shape == PressShape::kPunch && !object.half_size_mm)
    reader.Fail("'half_size_mm' [a, b] (> 0) is required for a punch");
  if (object.shape != PressShape::kPunch) refuse("half_size_mm", "is a punch's, not a " + shape + "'s");
  if (object.shape != PressShape::kPair) {
    refuse("objects", "are a pair's, not a " + shape + "'s");
    refuse("split", "is a pair's, not a " + shape + "'s");
    if (!object.position_mm && object.shape != PressShape::kFlat)
      reader.Fail("'position_mm' [x, y] is required for a " + shape);
    return;
  }
  refuse("position_mm", "is each of a pair's objects', not the pair's");
  refuse("yaw_deg", "is each of a pair's objects', not the pair's");
  if (object.objects.size() != 2) reader.Fail(reader.Has("objects") ? reader.Node("objects") : node, "a pair needs 'objects': two of them");
  if (!reader.Has("split")) reader.Fail("'split' [s1, s2] (each object's share of force_N) is required for a pair");
  const YAML::Node split = reader.Node("split");
  double sum = 0;
  for (double s : object.split) sum += s;
  if (object.split.size() != object.objects.size() || std::abs(sum - 1) > 1e-6)
    reader.Fail(split, "'split' must give each of the pair's objects a share in [0, 1], the shares summing to 1");
  const YAML::Node objects = reader.Node("objects");
  for (std::size_t j = 0; j < object.objects.size(); ++j) CheckObject(object.objects[j], objects[j], file, true);
}

ContactPrimitive PrimitiveOf(const PressObjectKeys& o, double force_N, const std::array<double, 2>& traction) {
  ContactPrimitive p;
  p.shape = o.shape == PressShape::kCylinder ? ContactShape::kCylinder
            : o.shape == PressShape::kFlat   ? ContactShape::kFlat
                                             : ContactShape::kSphere;
  p.x_mm = o.position_mm ? (*o.position_mm)[0] : 0.0;
  p.y_mm = o.position_mm ? (*o.position_mm)[1] : 0.0;
  p.radius_mm = o.radius_mm.value_or(0.0);
  p.yaw_deg = o.yaw_deg;
  p.length_mm = o.length_mm.value_or(0.0);
  p.normal_force_N = force_N;
  p.shear_x_N = traction[0] * force_N;
  p.shear_y_N = traction[1] * force_N;
  return p;
}

PressedObject Pressed(const PressObjectKeys& o, double force_N, double share, const std::array<double, 2>& traction) {
  PressedObject p;
  p.shape = o.shape;
  p.primitive = PrimitiveOf(o, share * force_N, traction);
  if (o.half_size_mm) {
    p.half_size_mm[0] = (*o.half_size_mm)[0];
    p.half_size_mm[1] = (*o.half_size_mm)[1];
  }
  p.share = share;
  return p;
}

void DecodeLog(const std::string& cases_file, const SensorProfile& profile, CalibrationPress* p) {
  std::ifstream in(p->log_path);
  if (!in) throw std::runtime_error(cases_file + ": cannot open log '" + p->log_path + "'");
  CandumpLogReader reader(in, p->log_path);
  ScanAssembler assembler(profile);
  Frame f;
  while (reader.Next(&f)) assembler.Push(f, &p->scans);
  assembler.Flush(&p->scans);
  if (p->scans.empty()) throw std::runtime_error(p->log_path + ": no scan of profile '" + profile.name + "'");
  const int64_t t0 = p->scans.front().utime;
  for (const Scan& s : p->scans) {
    p->t_s.push_back(1e-6 * static_cast<double>(s.utime - t0));
    p->readings_N.push_back(ScanReadings_N(s, profile));
  }
}

}  // namespace

std::vector<CalibrationPress> LoadCalibrationPresses(const std::string& cases_json, const SensorProfile& profile) {
  const config::YamlDocument doc = config::LoadYamlFile(cases_json);
  config::MapReader root(doc.root, doc.file);
  CasesFile file;
  config::ReadYaml(root, &file);
  const std::string dir = cases_json.find('/') == std::string::npos ? "." : cases_json.substr(0, cases_json.rfind('/'));
  std::vector<CalibrationPress> presses;
  for (std::size_t i = 0; i < file.cases.size(); ++i) {
    const PressCaseKeys& c = file.cases[i];
    CheckObject(c.object, doc.root["cases"][i]["object"], doc.file, false);
    CalibrationPress p;
    // Relative to the cases file, or as given when absolute (a selection of presses kept
    // elsewhere, e.g. a held-out set); the name is the file's own.
    const bool absolute = !c.log.empty() && c.log[0] == '/';
    p.name = absolute ? c.log.substr(c.log.rfind('/') + 1) : c.log;
    p.log_path = absolute ? c.log : dir + "/" + c.log;
    p.shape = c.object.shape;
    if (p.shape == PressShape::kPair) {
      for (std::size_t j = 0; j < c.object.objects.size(); ++j)
        p.objects.push_back(Pressed(c.object.objects[j], c.force_N, c.object.split[j], c.object.traction));
    } else {
      p.objects.push_back(Pressed(c.object, c.force_N, 1.0, c.object.traction));
      if (p.is_primitive()) p.object = p.objects[0].primitive;
    }
    p.protocol = file.protocol;
    DecodeLog(doc.file, profile, &p);
    presses.push_back(std::move(p));
  }
  return presses;
}

}  // namespace sedbridge::sensors
