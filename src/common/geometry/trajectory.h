#pragma once
// Prescribed rigid motion: keyframed pose (linear position, slerped orientation) plus an
// optional sinusoidal vibration. Used for indenters, the pressing plane and the tracked
// bone pose.

#include <Eigen/Geometry>
#include <vector>

namespace sedbridge::geometry {

struct PoseKeyframe {
  double t_s = 0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

struct Vibration {
  double amplitude_m = 0;
  double frequency_Hz = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< unit
};

class Trajectory {
 public:
  /// A fixed pose.
  explicit Trajectory(const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity());
  /// Keyframes sorted by time (checked); before the first / after the last the pose holds.
  explicit Trajectory(std::vector<PoseKeyframe> keyframes, Vibration vibration = {});

  /// frame_from_object at time t.
  Eigen::Isometry3d Pose(double t_s) const;
  /// Velocity [m/s] of the object-fixed point that is at `p_frame_m` at time t.
  Eigen::Vector3d PointVelocity(const Eigen::Vector3d& p_frame_m, double t_s) const;
  /// Last keyframe time (0 for a fixed pose).
  double EndTime() const;
  /// The same motion seen from another frame: Pose'(t) = frame_from_this * Pose(t).
  Trajectory Transformed(const Eigen::Isometry3d& frame_from_this) const;

 private:
  std::vector<PoseKeyframe> keyframes_;
  Vibration vibration_;
};

}  // namespace sedbridge::geometry
