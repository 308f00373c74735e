#include "common/geometry/rigid_object.h"

#include <filesystem>

namespace sedbridge::geometry {

namespace {

Eigen::Vector3d Vec3(config::MapReader& r, const std::string& key, const Eigen::Vector3d& fallback) {
  if (!r.Has(key)) return fallback;
  const YAML::Node n = r.Node(key);
  auto v = config::As<std::vector<double>>(n, r.file(), key);
  if (v.size() != 3) r.Fail(n, "'" + key + "' needs 3 numbers");
  return {v[0], v[1], v[2]};
}

/// A required (or, with a fallback, optional) strictly positive length in mm, returned in m.
double PositiveMm(config::MapReader& r, const std::string& key, double fallback_mm = -1) {
  if (!r.Has(key) && fallback_mm > 0) return fallback_mm * 1e-3;
  const double v = r.Required<double>(key);
  if (!(v > 0)) r.Fail(r.Node(key), "'" + key + "' must be > 0");
  return v * 1e-3;
}

}  // namespace

Eigen::Matrix3d RotationFromRpyDeg(const Eigen::Vector3d& rpy_deg) {
  const Eigen::Vector3d r = rpy_deg * M_PI / 180.0;
  return (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

SdfSample RigidObject::Evaluate(const Eigen::Vector3d& p, double t) const {
  const Eigen::Isometry3d pose = trajectory.Pose(t);
  SdfSample s = shape->Evaluate(pose.inverse() * p);
  s.normal = pose.linear() * s.normal;
  return s;
}

RigidObject ParseRigidObject(config::MapReader& r) {
  RigidObject obj;
  const std::string kind = r.RequiredChoice(
      "shape", {"plane", "sphere", "cylinder", "edge", "box", "grating", "grid"});
  obj.name = r.Optional<std::string>("name", kind);
  if (kind == "plane") {
    obj.shape = std::make_shared<PlaneSdf>();
  } else if (kind == "sphere") {
    obj.shape = std::make_shared<SphereSdf>(PositiveMm(r, "radius_mm"));
  } else if (kind == "cylinder" || kind == "edge") {
    const double radius = kind == "edge" ? PositiveMm(r, "radius_mm", 0.25) : PositiveMm(r, "radius_mm");
    const double half_length = r.Has("length_mm") ? 0.5 * PositiveMm(r, "length_mm") : 0.0;
    obj.shape = std::make_shared<CylinderSdf>(radius, half_length);
  } else if (kind == "box") {
    r.Required<std::vector<double>>("size_mm");  // "missing" error when absent
    const Eigen::Vector3d size = Vec3(r, "size_mm", {}) * 1e-3;
    if ((size.array() <= 0).any()) r.Fail(r.Node("size_mm"), "'size_mm' entries must be > 0");
    const double rounding = r.Optional<double>("rounding_mm", 0.0) * 1e-3;
    if (rounding < 0 || 2 * rounding > size.minCoeff()) r.Fail("'rounding_mm' must be in [0, min(size)/2]");
    obj.shape = std::make_shared<BoxSdf>(0.5 * size, rounding);
  } else if (kind == "grating") {
    const double period = PositiveMm(r, "period_mm");
    const double width = PositiveMm(r, "ridge_width_mm");
    if (width >= period) r.Fail(r.Node("ridge_width_mm"), "'ridge_width_mm' must be < 'period_mm'");
    obj.shape = std::make_shared<GratingSdf>(period, width, PositiveMm(r, "depth_mm"));
  } else {
    std::string path = r.Required<std::string>("file");
    if (!std::filesystem::path(path).is_absolute())
      path = (std::filesystem::path(r.file()).parent_path() / path).string();
    obj.shape = std::make_shared<GridSdf>(GridSdf::Load(path));
  }

  Eigen::Isometry3d pose0 = Eigen::Isometry3d::Identity();
  pose0.translation() = Vec3(r, "position_mm", Eigen::Vector3d::Zero()) * 1e-3;
  pose0.linear() = RotationFromRpyDeg(Vec3(r, "rpy_deg", Eigen::Vector3d::Zero()));

  if (!r.Has("motion")) {
    obj.trajectory = Trajectory(pose0);
    return obj;
  }
  config::MapReader motion = r.Child("motion");
  obj.trajectory = ParseMotion(motion, pose0);
  motion.Finish();
  return obj;
}

Trajectory ParseMotion(config::MapReader& motion, const Eigen::Isometry3d& pose0) {
  std::vector<PoseKeyframe> keys;
  if (motion.Has("keyframes")) {
    const YAML::Node list = motion.Node("keyframes");
    if (!list.IsSequence() || list.size() == 0) motion.Fail(list, "'keyframes' must be a non-empty list");
    for (const auto& item : list) {
      config::MapReader k(item, motion.file());
      PoseKeyframe key;
      key.t_s = k.Required<double>("t_s");
      key.position_m = pose0.translation() + Vec3(k, "offset_mm", Eigen::Vector3d::Zero()) * 1e-3;
      key.orientation = Eigen::Quaterniond(pose0.linear() * RotationFromRpyDeg(Vec3(k, "rpy_deg", Eigen::Vector3d::Zero())));
      if (!keys.empty() && !(key.t_s > keys.back().t_s)) k.Fail(item, "keyframe times must increase");
      k.Finish();
      keys.push_back(key);
    }
  } else {
    PoseKeyframe key;
    key.position_m = pose0.translation();
    key.orientation = Eigen::Quaterniond(pose0.linear());
    keys.push_back(key);
  }
  Vibration vib;
  if (motion.Has("vibration")) {
    config::MapReader v = motion.Child("vibration");
    vib.amplitude_m = v.Required<double>("amplitude_mm") * 1e-3;
    vib.frequency_Hz = v.Required<double>("frequency_Hz");
    if (!(vib.frequency_Hz > 0)) v.Fail(v.Node("frequency_Hz"), "'frequency_Hz' must be > 0");
    vib.direction = Vec3(v, "direction", Eigen::Vector3d::UnitZ());
    if (vib.direction.norm() == 0) v.Fail(v.Node("direction"), "'direction' must be non-zero");
    v.Finish();
  }
  return Trajectory(std::move(keys), vib);
}

std::vector<RigidObject> ParseRigidObjects(const YAML::Node& list, const std::string& file) {
  if (!list.IsSequence()) throw config::ConfigError(config::LocationOf(list, file), "expected a list of objects");
  std::vector<RigidObject> out;
  for (const auto& item : list) {
    config::MapReader r(item, file);
    out.push_back(ParseRigidObject(r));
    r.Finish();
  }
  return out;
}

}  // namespace sedbridge::geometry
