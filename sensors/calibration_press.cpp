#include "sensors/calibration_press.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "common/yaml_reader.h"
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

ContactPrimitive CalibrationPress::ObjectAt(double t, const PressProtocol& protocol) const {
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

std::vector<CalibrationPress> LoadCalibrationPresses(const std::string& cases_json, const SensorProfile& profile) {
  const config::YamlDocument doc = config::LoadYamlFile(cases_json);
  config::MapReader root(doc.root, doc.file);
  const YAML::Node list = root.Node("cases");
  root.Finish();
  if (!list.IsSequence()) root.Fail(list, "'cases' must be a list");
  const std::string dir = cases_json.find('/') == std::string::npos ? "." : cases_json.substr(0, cases_json.rfind('/'));
  std::vector<CalibrationPress> presses;
  for (const YAML::Node& entry : list) {
    config::MapReader e(entry, doc.file);
    CalibrationPress p;
    p.name = e.Required<std::string>("log");
    p.log_path = dir + "/" + p.name;
    const double force = e.Required<double>("force_N");
    if (!(force > 0) || force > 1e3) e.Fail(e.Node("force_N"), "'force_N' must be in (0, 1000]");
    config::MapReader o = e.Child("object");
    const std::string shape = o.RequiredChoice("shape", {"sphere", "cylinder", "flat"});
    p.object.shape = ContactShapeFromName(shape);
    const auto pos = o.Required<std::vector<double>>("position_mm");
    if (pos.size() != 2) o.Fail(o.Node("position_mm"), "'position_mm' needs [x, y]");
    p.object.x_mm = pos[0];
    p.object.y_mm = pos[1];
    p.object.radius_mm = o.Optional<double>("radius_mm", p.object.shape == ContactShape::kFlat ? 0.0 : -1.0);
    if (p.object.shape != ContactShape::kFlat && !(p.object.radius_mm > 0))
      o.Fail("'radius_mm' (> 0) is required for a " + shape);
    p.object.yaw_deg = o.Optional<double>("yaw_deg", 0.0);
    const auto traction = o.Optional<std::vector<double>>("traction", {0.0, 0.0});
    if (traction.size() != 2) o.Fail(o.Node("traction"), "'traction' needs [x, y]");
    o.Finish();
    e.Finish();
    p.object.normal_force_N = force;
    p.object.shear_x_N = traction[0] * force;
    p.object.shear_y_N = traction[1] * force;

    std::ifstream in(p.log_path);
    if (!in) throw std::runtime_error(doc.file + ": cannot open log '" + p.log_path + "'");
    CandumpLogReader reader(in, p.log_path);
    ScanAssembler assembler(profile);
    Frame f;
    while (reader.Next(&f)) assembler.Push(f, &p.scans);
    assembler.Flush(&p.scans);
    if (p.scans.empty()) throw std::runtime_error(p.log_path + ": no scan of profile '" + profile.name + "'");
    const int64_t t0 = p.scans.front().utime;
    for (const Scan& s : p.scans) {
      p.t_s.push_back(1e-6 * static_cast<double>(s.utime - t0));
      p.readings_N.push_back(ScanReadings_N(s, profile));
    }
    presses.push_back(std::move(p));
  }
  return presses;
}

}  // namespace sedbridge::sensors
