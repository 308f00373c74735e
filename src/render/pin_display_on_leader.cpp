#include "render/pin_display_on_leader.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "common/geometry/signed_distance_field.h"

namespace sedbridge::render {

namespace {

constexpr double kMm = 1e-3;
// The pin's body above its tip [m]: longer than any travel plus the preload, so the skin
// only ever meets its tip and sides.
constexpr double kPinHalfLength_m = 10e-3;

geometry::RigidObject Plate(double depth_mm) {
  // PlaneSdf is the half-space z < 0 of its frame: turned over, its solid is z > -depth.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0, 0, -depth_mm * kMm);
  return {"display plate", std::make_shared<geometry::PlaneSdf>(), geometry::Trajectory(pose)};
}

}  // namespace

PinDisplayOnLeader::PinDisplayOnLeader(scene::FingertipCompliance& leader, const display::DisplayDevice& device)
    : leader_(leader), device_(device) {
  if (device.kind != display::DisplayKind::kPin || device.footprints.empty())
    throw std::invalid_argument("pin display on the leader: needs a pin display's device model");
  preload_force_N_ = PreloadForce_N(device);
  leader_.ResetWarmStart();
  const scene::PressToForceResult r = leader_.PressToForce({Plate(0.0)}, preload_force_N_);
  if (!r.reached)
    throw std::runtime_error(std::string("pin display on the leader: the preload press failed: ") +
                             scene::ToString(r.status) + " " + r.message);
  preload_depth_mm_ = r.indentation_mm;
}

std::vector<geometry::RigidObject> PinDisplayOnLeader::Objects(const Eigen::VectorXd& heights_mm) const {
  std::vector<geometry::RigidObject> objects{Plate(preload_depth_mm_)};
  const double radius_m = device_.pin_radius_mm * kMm;
  for (size_t i = 0; i < device_.footprints.size(); ++i) {
    const double h = heights_mm[Eigen::Index(i)];
    if (!(h > 0)) continue;  // a pin at rest is under the plate's surface
    const display::ActuatorFootprint& f = device_.footprints[i];
    const double tip_z_m = -(preload_depth_mm_ + h) * kMm;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    std::shared_ptr<geometry::SignedDistanceField> shape;
    if (device_.tip == display::PinTip::kRounded) {
      // The tip's spherical cap (the part a pin within its travel presses with).
      const double R = device_.tip_radius_mm * kMm;
      pose.translation() = Eigen::Vector3d(f.x_mm * kMm, f.y_mm * kMm, tip_z_m + R);
      shape = std::make_shared<geometry::SphereSdf>(R);
    } else {
      // A flat-ended cylinder along pad z (CylinderSdf runs along its frame's x).
      pose.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
      pose.translation() = Eigen::Vector3d(f.x_mm * kMm, f.y_mm * kMm, tip_z_m + kPinHalfLength_m);
      shape = std::make_shared<geometry::CylinderSdf>(radius_m, kPinHalfLength_m);
    }
    objects.push_back({"pin " + std::to_string(i), shape, geometry::Trajectory(pose)});
  }
  return objects;
}

bool PinDisplayOnLeader::Press(const Eigen::VectorXd& heights_mm, Eigen::VectorXd& sed_Pa) {
  error_.clear();
  if (heights_mm.size() != num_actuators() || !heights_mm.allFinite() || (heights_mm.array() < 0).any()) {
    error_ = "one finite height >= 0 per pin";
    return false;
  }
  // Raised in steps no longer than a pin's radius: the contact's SDF is evaluated at the
  // displaced nodes, and a long jump lets nodes tunnel past a thin pin.
  const double top = heights_mm.maxCoeff();
  const int steps = std::max(1, int(std::ceil(top / std::max(0.1, 0.5 * device_.pin_radius_mm))));
  leader_.ResetWarmStart();
  for (int s = 1; s <= steps; ++s) {
    const fem::ComplianceStepResult& r = leader_.Step(Objects(heights_mm * (double(s) / steps)));
    if (!r.ok || !r.converged) {
      error_ = "contact solve failed: " + (r.error.empty() ? std::string("not converged") : r.error);
      return false;
    }
  }
  sed_Pa = leader_.sed_Pa();
  return true;
}

double PinDisplayOnLeader::default_reference_command() const {
  return std::min(0.2, 0.2 * device_.travel_mm);
}

ElementStrainInfluence PinDisplayOnLeader::Influence(double reference_height_mm) {
  if (!(reference_height_mm > 0)) throw std::invalid_argument("pin display influence: reference height > 0");
  return InfluenceByPresses(*this, leader_, reference_height_mm, "pin display");
}

}  // namespace sedbridge::render
