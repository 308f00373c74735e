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

namespace {

using config::Field;

/// `object` of one case in cases.json: the object at the peak force.
struct PressObjectKeys {
  ContactShape shape = ContactShape::kSphere;
  std::array<double, 2> position_mm{};
  std::optional<double> radius_mm;  ///< > 0, required for a sphere or a cylinder
  double yaw_deg = 0;
  std::array<double, 2> traction{0, 0};  ///< tangential force / normal force

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(Field("shape", &shape).Required());
    a->Visit(Field("position_mm", &position_mm).Required());
    a->Visit(Field("radius_mm", &radius_mm));
    a->Visit(Field("yaw_deg", &yaw_deg));
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

// A flat's radius is never used, so only a sphere or cylinder needs one.
void CheckRadius(const PressObjectKeys& object, const config::MapReader& object_reader) {
  if (object.shape == ContactShape::kFlat || object.radius_mm.value_or(-1) > 0) return;
  object_reader.Fail("'radius_mm' (> 0) is required for a " + std::string(ContactShapeName(object.shape)));
}

ContactPrimitive PeakObject(const PressCaseKeys& c) {
  ContactPrimitive o;
  o.shape = c.object.shape;
  o.x_mm = c.object.position_mm[0];
  o.y_mm = c.object.position_mm[1];
  o.radius_mm = c.object.radius_mm.value_or(0.0);
  o.yaw_deg = c.object.yaw_deg;
  o.normal_force_N = c.force_N;
  o.shear_x_N = c.object.traction[0] * c.force_N;
  o.shear_y_N = c.object.traction[1] * c.force_N;
  return o;
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
    CheckRadius(c.object, config::MapReader(doc.root["cases"][i]["object"], doc.file));
    CalibrationPress p;
    // Relative to the cases file, or as given when absolute (a selection of presses kept
    // elsewhere, e.g. a held-out set); the name is the file's own.
    const bool absolute = !c.log.empty() && c.log[0] == '/';
    p.name = absolute ? c.log.substr(c.log.rfind('/') + 1) : c.log;
    p.log_path = absolute ? c.log : dir + "/" + c.log;
    p.object = PeakObject(c);
    p.protocol = file.protocol;
    DecodeLog(doc.file, profile, &p);
    presses.push_back(std::move(p));
  }
  return presses;
}

}  // namespace sedbridge::sensors
