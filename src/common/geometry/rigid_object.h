#pragma once
// A rigid scene object: a shape (SDF in its own frame) moving on a trajectory in the
// scene frame. Parsed from YAML (see ParseRigidObjects for the keys).

#include <memory>
#include <string>
#include <vector>

#include "common/geometry/signed_distance_field.h"
#include "common/geometry/trajectory.h"

namespace sedbridge::config {
class MapReader;
}

namespace sedbridge::geometry {

struct RigidObject {
  std::string name;
  std::shared_ptr<const SignedDistanceField> shape;
  Trajectory trajectory;

  /// Distance/normal of scene-frame point `p_m` at time t (normal in the scene frame).
  SdfSample Evaluate(const Eigen::Vector3d& p_m, double t_s) const;
};

/// Parses one object mapping:
///   name: indenter                 # optional, defaults to the shape name
///   shape: plane | sphere | cylinder | edge | box | grating | grid
///   radius_mm: 5                   # sphere, cylinder, edge (edge default 0.25)
///   length_mm: 20                  # cylinder/edge, optional (infinite if absent)
///   size_mm: [10, 10, 10]          # box; rounding_mm: 0 optional
///   period_mm, ridge_width_mm, depth_mm   # grating
///   file: path.sdf                 # grid (see GridSdf::Load), relative to the YAML
///   position_mm: [x, y, z]         # pose at t = 0 (scene frame)
///   rpy_deg: [roll, pitch, yaw]    # orientation, applied as Rz(yaw) Ry(pitch) Rx(roll)
///   motion:                        # optional
///     keyframes: [{t_s: 0, offset_mm: [0,0,0]}, {t_s: 0.05, offset_mm: [0,0,-2]}]
///     vibration: {amplitude_mm: 0.1, frequency_Hz: 300, direction: [0,0,1]}
/// keyframe offsets translate the t = 0 pose (in the scene frame); a keyframe may also
/// give rpy_deg, a rotation applied after the t = 0 orientation.
RigidObject ParseRigidObject(config::MapReader& reader);

/// Parses a `motion` mapping (keyframes, vibration) around the t = 0 pose `pose0`.
Trajectory ParseMotion(config::MapReader& motion, const Eigen::Isometry3d& pose0);

/// Parses the list of object mappings under `key` of `owner` (required; may be empty).
std::vector<RigidObject> ParseRigidObjects(config::MapReader& owner, const std::string& key);

/// Rotation from roll/pitch/yaw in degrees: Rz(yaw) * Ry(pitch) * Rx(roll).
Eigen::Matrix3d RotationFromRpyDeg(const Eigen::Vector3d& rpy_deg);

}  // namespace sedbridge::geometry
