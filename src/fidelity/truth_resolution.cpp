#include "fidelity/truth_resolution.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "contact/contact_object.h"
#include "model/fingertip_model.h"
#include "scene/fingertip_compliance.h"
#include "sensors/calibration_press.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::fidelity {

std::vector<Eigen::Vector2d> ShiftGrid(double step_mm, int per_side) {
  std::vector<Eigen::Vector2d> shifts;
  for (int j = 0; j < per_side; ++j)
    for (int i = 0; i < per_side; ++i) shifts.emplace_back(i * step_mm, j * step_mm);
  return shifts;
}

ShiftedTruthLeader::ShiftedTruthLeader(const std::string& model_name, bool face_contact, const std::string& cache_dir)
    : model_name_(model_name),
      face_contact_(face_contact),
      model_(std::make_unique<model::FingertipModel>(model::LoadFingertipModel(model_name))),
      leader_(std::make_unique<scene::FingertipCompliance>(*model_,
                                                           contact::LeaderComplianceOptions(cache_dir, face_contact))) {}

ShiftedTruthLeader::~ShiftedTruthLeader() = default;

std::vector<TruthShiftRow> ShiftedTruthLeader::PressAtShifts(const std::string& label,
                                                             const sensors::ContactPrimitive& object, double force_N,
                                                             const std::vector<Eigen::Vector2d>& shifts_mm) {
  scene::FingertipCompliance& leader = *leader_;
  std::vector<TruthShiftRow> rows;
  for (const Eigen::Vector2d& shift : shifts_mm) {
    sensors::ContactPrimitive moved = object;
    moved.x_mm += shift.x();
    moved.y_mm += shift.y();
    TruthShiftRow row;
    row.object = label;
    row.model = model_name_;
    row.face_contact = face_contact_;
    row.force_N = force_N;
    row.dx_mm = shift.x();
    row.dy_mm = shift.y();
    leader.ResetWarmStart();  // each shift from scratch: no shift's answer leans on another's
    const scene::PressToForceResult r = leader.PressToForce({contact::ToRigidObject(moved)}, force_N);
    row.reached = contact::PressAnswered(r, leader);
    row.depth_mm = r.indentation_mm;
    row.contact_points = r.active_nodes;
    if (row.reached) {
      row.peak_sed_Pa = leader.sed_Pa().maxCoeff();
      row.sum_sed_Pa = leader.sed_Pa().sum();
    }
    rows.push_back(row);
  }
  return rows;
}

TruthSpread SpreadOf(const std::vector<TruthShiftRow>& rows) {
  TruthSpread s;
  s.shifts = int(rows.size());
  std::vector<double> peak, sum;
  for (const TruthShiftRow& r : rows)
    if (r.reached) peak.push_back(r.peak_sed_Pa), sum.push_back(r.sum_sed_Pa);
  s.reached = int(peak.size());
  if (peak.empty()) return s;
  std::vector<double> sorted = peak;
  std::sort(sorted.begin(), sorted.end());
  s.peak_median_Pa = sorted[sorted.size() / 2];
  auto ratio = [](const std::vector<double>& v) {
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    return *hi > 0 ? *lo / *hi : 0.0;
  };
  s.peak_min_over_max = ratio(peak);
  s.sum_min_over_max = ratio(sum);
  return s;
}

double LogRadiusSigmaPerScan(const sensors::SensorProfile& profile, const sensors::ContactPrimitive& object,
                             double noise_counts) {
  if (!profile.has_forward_model) throw std::invalid_argument("sensor profile '" + profile.name + "' has no forward_model");
  if (object.shape != sensors::ContactShape::kSphere && object.shape != sensors::ContactShape::kCylinder)
    throw std::invalid_argument("LogRadiusSigmaPerScan: a sphere or a rod");
  const sensors::TactileForwardModel model(profile, profile.forward_model);
  const int channels = 3 * profile.taxel_count;
  Eigen::VectorXd inv_sigma(channels);
  for (int k = 0; k < profile.taxel_count; ++k)
    for (int a = 0; a < 3; ++a) inv_sigma[3 * k + a] = 1.0 / (noise_counts * sensors::NewtonsPerCount(profile, k, a));
  // Central differences in the place [mm] (a rod: across its axis only, along it nothing
  // changes), log F and log R: the whitened Jacobian, then the log R entry of the inverse of
  // its information.
  const bool rod = object.shape == sensors::ContactShape::kCylinder;
  const double yaw = object.yaw_deg * M_PI / 180;
  const Eigen::Vector2d across(-std::sin(yaw), std::cos(yaw));
  auto predict = [&](int parameter, double h) {
    sensors::ContactPrimitive c = object;
    if (parameter == 0) c.x_mm += rod ? h * across.x() : h;
    if (parameter == 1) c.y_mm += rod ? h * across.y() : h;
    if (parameter == 2) c.normal_force_N *= std::exp(h);
    if (parameter == 3) c.radius_mm *= std::exp(h);
    Eigen::VectorXd readings;
    model.Predict(c, &readings);
    return readings;
  };
  const std::vector<int> parameters = rod ? std::vector<int>{0, 2, 3} : std::vector<int>{0, 1, 2, 3};
  constexpr double kStep[4] = {0.01, 0.01, 1e-3, 1e-3};
  Eigen::MatrixXd J(channels, Eigen::Index(parameters.size()));
  for (size_t i = 0; i < parameters.size(); ++i) {
    const int p = parameters[i];
    J.col(Eigen::Index(i)) = (predict(p, kStep[p]) - predict(p, -kStep[p])).cwiseProduct(inv_sigma) / (2 * kStep[p]);
  }
  const Eigen::MatrixXd information = J.transpose().lazyProduct(J);  // lazy: no OpenMP team for a 4 x 4
  const Eigen::MatrixXd covariance = information.inverse();
  const Eigen::Index r = covariance.rows() - 1;
  return covariance(r, r) > 0 ? std::sqrt(covariance(r, r)) : std::numeric_limits<double>::infinity();
}

void WriteTruthShiftCsv(const std::string& path, const std::vector<TruthShiftRow>& rows) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << "object,model,contact,force_N,dx_mm,dy_mm,reached,depth_mm,peak_sed_Pa,sum_sed_Pa,contact_points\n";
  char buf[256];
  for (const TruthShiftRow& r : rows) {
    std::snprintf(buf, sizeof buf, ",%s,%s,%.4g,%.4g,%.4g,%d,%.6g,%.6g,%.6g,%d\n", r.model.c_str(),
                  r.face_contact ? "face" : "node", r.force_N, r.dx_mm, r.dy_mm, r.reached ? 1 : 0, r.depth_mm,
                  r.peak_sed_Pa, r.sum_sed_Pa, r.contact_points);
    f << '"' << r.object << '"' << buf;
  }
  if (!f) throw std::runtime_error("write failed: " + path);
}

}  // namespace sedbridge::fidelity
