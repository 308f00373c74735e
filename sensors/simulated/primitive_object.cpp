#include "sensors/simulated/primitive_object.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "common/geometry/signed_distance_field.h"

namespace sedbridge::sensors {

geometry::RigidObject RigidObjectOf(const ContactPrimitive& p, double rod_half_length_m, double min_radius_mm) {
  geometry::RigidObject o;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const double r_m = std::max(p.radius_mm, min_radius_mm) * 1e-3;
  switch (p.shape) {
    case ContactShape::kSphere:
      o.name = "sphere";
      o.shape = std::make_shared<geometry::SphereSdf>(r_m);
      pose.translation() = Eigen::Vector3d(p.x_mm * 1e-3, p.y_mm * 1e-3, r_m);
      break;
    case ContactShape::kCylinder:
      o.name = "cylinder";
      o.shape = std::make_shared<geometry::CylinderSdf>(r_m, p.length_mm > 0 ? 0.5e-3 * p.length_mm : rod_half_length_m);
      pose.linear() = geometry::RotationFromRpyDeg(Eigen::Vector3d(0, 0, p.yaw_deg));
      pose.translation() = Eigen::Vector3d(p.x_mm * 1e-3, p.y_mm * 1e-3, r_m);
      break;
    case ContactShape::kPunch: {
      o.name = "punch";
      const Eigen::Vector3d half_m(p.half_size_mm[0] * 1e-3, p.half_size_mm[1] * 1e-3, 0.5e-3 * kPunchHeight_mm);
      o.shape = std::make_shared<geometry::BoxSdf>(half_m, std::min(kPunchRounding_mm * 1e-3, half_m.minCoeff()));
      pose.linear() = geometry::RotationFromRpyDeg(Eigen::Vector3d(0, 0, p.yaw_deg));
      pose.translation() = Eigen::Vector3d(p.x_mm * 1e-3, p.y_mm * 1e-3, half_m.z());
      break;
    }
    case ContactShape::kRoundPunch: {
      // A capped cylinder standing on its face (its axis, the object's x, turned to z), as a
      // scene presses one.
      o.name = "round_punch";
      const double half_height_m = 0.5e-3 * kPunchHeight_mm;
      o.shape = std::make_shared<geometry::CylinderSdf>(std::max(p.radius_mm, 0.0) * 1e-3, half_height_m);
      pose.linear() = geometry::RotationFromRpyDeg(Eigen::Vector3d(0, 90, 0));
      pose.translation() = Eigen::Vector3d(p.x_mm * 1e-3, p.y_mm * 1e-3, half_height_m);
      break;
    }
    case ContactShape::kCorner: {
      // A sharp cube kCornerCubeSide_mm on a side with a corner pointing straight down (its
      // body diagonal vertical: roll 45, pitch atan(1 / sqrt(2))), turned by the yaw, that
      // corner on the pad at (x, y), as a scene presses one.
      o.name = "corner";
      const double half_m = 0.5e-3 * kCornerCubeSide_mm;
      o.shape = std::make_shared<geometry::BoxSdf>(Eigen::Vector3d::Constant(half_m), 0.0);
      pose.linear() = geometry::RotationFromRpyDeg(Eigen::Vector3d(45, std::atan(std::sqrt(0.5)) * 180 / M_PI, p.yaw_deg));
      double lowest = 0;
      Eigen::Vector3d tip = Eigen::Vector3d::Zero();
      for (int k = 0; k < 8; ++k) {
        const Eigen::Vector3d v = pose.linear() * Eigen::Vector3d((k & 1) ? half_m : -half_m, (k & 2) ? half_m : -half_m,
                                                                  (k & 4) ? half_m : -half_m);
        if (k == 0 || v.z() < lowest) lowest = v.z(), tip = v;
      }
      pose.translation() = Eigen::Vector3d(p.x_mm * 1e-3, p.y_mm * 1e-3, 0) - tip;
      break;
    }
    case ContactShape::kFlat:
      o.name = "flat";
      o.shape = std::make_shared<geometry::PlaneSdf>();
      pose.linear() = geometry::RotationFromRpyDeg(Eigen::Vector3d(180, 0, 0));  // solid above z = 0
      break;
  }
  o.trajectory = geometry::Trajectory(pose);
  return o;
}

}  // namespace sedbridge::sensors
