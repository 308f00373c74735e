#include "common/geometry/trajectory.h"

#include <cmath>
#include <stdexcept>

namespace sedbridge::geometry {

Trajectory::Trajectory(const Eigen::Isometry3d& pose) {
  PoseKeyframe k;
  k.position_m = pose.translation();
  k.orientation = Eigen::Quaterniond(pose.rotation());
  keyframes_.push_back(k);
}

Trajectory::Trajectory(std::vector<PoseKeyframe> keyframes, Vibration vibration)
    : keyframes_(std::move(keyframes)), vibration_(vibration) {
  if (keyframes_.empty()) keyframes_.push_back({});
  for (size_t i = 1; i < keyframes_.size(); ++i)
    if (!(keyframes_[i].t_s > keyframes_[i - 1].t_s))
      throw std::invalid_argument("trajectory keyframe times must increase");
  for (auto& k : keyframes_) k.orientation.normalize();
  if (vibration_.direction.norm() > 0) vibration_.direction.normalize();
}

Eigen::Isometry3d Trajectory::Pose(double t) const {
  Eigen::Vector3d p;
  Eigen::Quaterniond q;
  if (t <= keyframes_.front().t_s) {
    p = keyframes_.front().position_m;
    q = keyframes_.front().orientation;
  } else if (t >= keyframes_.back().t_s) {
    p = keyframes_.back().position_m;
    q = keyframes_.back().orientation;
  } else {
    size_t i = 1;
    while (keyframes_[i].t_s < t) ++i;
    const PoseKeyframe& a = keyframes_[i - 1];
    const PoseKeyframe& b = keyframes_[i];
    const double s = (t - a.t_s) / (b.t_s - a.t_s);
    p = (1 - s) * a.position_m + s * b.position_m;
    q = a.orientation.slerp(s, b.orientation);
  }
  if (vibration_.amplitude_m != 0 && vibration_.frequency_Hz > 0)
    p += vibration_.amplitude_m * std::sin(2 * M_PI * vibration_.frequency_Hz * t) *
         vibration_.direction;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = p;
  return pose;
}

Eigen::Vector3d Trajectory::PointVelocity(const Eigen::Vector3d& p_frame, double t) const {
  // Central difference of the rigid motion; exact for the piecewise-linear part away from
  // keyframes and accurate to O(h^2) for the vibration.
  const double h = 1e-6;
  const Eigen::Vector3d p_object = Pose(t).inverse() * p_frame;
  return (Pose(t + h) * p_object - Pose(t - h) * p_object) / (2 * h);
}

double Trajectory::EndTime() const { return keyframes_.back().t_s; }

Trajectory Trajectory::Transformed(const Eigen::Isometry3d& frame_from_this) const {
  std::vector<PoseKeyframe> keys = keyframes_;
  const Eigen::Quaterniond q(frame_from_this.rotation());
  for (auto& k : keys) {
    k.position_m = frame_from_this * k.position_m;
    k.orientation = q * k.orientation;
  }
  Vibration v = vibration_;
  v.direction = frame_from_this.linear() * v.direction;
  return Trajectory(std::move(keys), v);
}

}  // namespace sedbridge::geometry
