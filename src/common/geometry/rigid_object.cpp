#include "common/geometry/rigid_object.h"

#include <filesystem>

#include "common/yaml_read_archive.h"

namespace sedbridge::geometry {

namespace {

using config::Field;

enum class ShapeKind { kPlane, kSphere, kCylinder, kEdge, kBox, kGrating, kGrid };
const config::EnumNames<ShapeKind>& NamesOf(ShapeKind) {
  static const config::EnumNames<ShapeKind> names{
      {ShapeKind::kPlane, "plane"}, {ShapeKind::kSphere, "sphere"},   {ShapeKind::kCylinder, "cylinder"},
      {ShapeKind::kEdge, "edge"},   {ShapeKind::kBox, "box"},         {ShapeKind::kGrating, "grating"},
      {ShapeKind::kGrid, "grid"}};
  return names;
}

/// One entry of `motion.keyframes`.
struct KeyframeKeys {
  double t_s = 0;
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(Field("t_s", &t_s).Required());
    a->Visit(Field("offset_mm", &offset_m).Scale(1e-3));
    a->Visit(Field("rpy_deg", &rpy_deg));
  }
};

/// `motion.vibration`.
struct VibrationKeys {
  Vibration vibration;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(Field("amplitude_mm", &vibration.amplitude_m).Required().Scale(1e-3));
    a->Visit(Field("frequency_Hz", &vibration.frequency_Hz).Required().Positive());
    a->Visit(Field("direction", &vibration.direction));
  }
};

/// A strictly positive length given in mm, in m; `required` or else `fallback_m`.
double LengthM(config::YamlReadArchive& a, const char* key, bool required, double fallback_m = 0) {
  double length_m = fallback_m;
  auto field = Field(key, &length_m).Positive().Scale(1e-3);
  if (required) field.Required();
  a.Visit(field);
  return length_m;
}

std::shared_ptr<const SignedDistanceField> ReadBox(config::YamlReadArchive& a) {
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();
  a.Visit(Field("size_mm", &size_m).Required().Positive().Scale(1e-3));
  double rounding_m = 0;
  a.Visit(Field("rounding_mm", &rounding_m).NonNegative().Scale(1e-3));
  if (2 * rounding_m > size_m.minCoeff())
    a.reader().Fail(a.reader().Node("rounding_mm"), "'rounding_mm' must be in [0, min(size)/2]");
  return std::make_shared<BoxSdf>(0.5 * size_m, rounding_m);
}

std::shared_ptr<const SignedDistanceField> ReadGrating(config::YamlReadArchive& a) {
  const double period_m = LengthM(a, "period_mm", true);
  const double width_m = LengthM(a, "ridge_width_mm", true);
  if (width_m >= period_m) a.reader().Fail(a.reader().Node("ridge_width_mm"), "'ridge_width_mm' must be < 'period_mm'");
  return std::make_shared<GratingSdf>(period_m, width_m, LengthM(a, "depth_mm", true));
}

std::shared_ptr<const SignedDistanceField> ReadGrid(config::YamlReadArchive& a) {
  std::string path;
  a.Visit(Field("file", &path).Required());
  // Relative to the YAML that names it, so a scene and its SDF move together.
  if (!std::filesystem::path(path).is_absolute())
    path = (std::filesystem::path(a.reader().file()).parent_path() / path).string();
  return std::make_shared<GridSdf>(GridSdf::Load(path));
}

std::shared_ptr<const SignedDistanceField> ReadShape(config::YamlReadArchive& a, ShapeKind kind) {
  switch (kind) {
    case ShapeKind::kPlane: return std::make_shared<PlaneSdf>();
    case ShapeKind::kSphere: return std::make_shared<SphereSdf>(LengthM(a, "radius_mm", true));
    case ShapeKind::kCylinder:
    case ShapeKind::kEdge: {
      // An edge is a thin cylinder: its radius has a default, a cylinder's has none.
      const bool edge = kind == ShapeKind::kEdge;
      const double radius_m = LengthM(a, "radius_mm", !edge, 0.25e-3);
      return std::make_shared<CylinderSdf>(radius_m, 0.5 * LengthM(a, "length_mm", false));  // 0: infinite
    }
    case ShapeKind::kBox: return ReadBox(a);
    case ShapeKind::kGrating: return ReadGrating(a);
    case ShapeKind::kGrid: return ReadGrid(a);
  }
  return nullptr;
}

Eigen::Isometry3d ReadInitialPose(config::YamlReadArchive& a) {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero(), rpy_deg = Eigen::Vector3d::Zero();
  a.Visit(Field("position_mm", &position_m).Scale(1e-3));
  a.Visit(Field("rpy_deg", &rpy_deg));
  Eigen::Isometry3d pose0 = Eigen::Isometry3d::Identity();
  pose0.translation() = position_m;
  pose0.linear() = RotationFromRpyDeg(rpy_deg);
  return pose0;
}

std::vector<PoseKeyframe> ReadKeyframes(config::MapReader& motion, const Eigen::Isometry3d& pose0) {
  std::vector<KeyframeKeys> given;
  config::YamlReadArchive a(&motion);
  a.Visit(Field("keyframes", &given).Required());
  const YAML::Node list = motion.node()["keyframes"];
  if (given.empty()) motion.Fail(list, "'keyframes' must be a non-empty list");
  std::vector<PoseKeyframe> keys;
  for (std::size_t i = 0; i < given.size(); ++i) {
    if (i > 0 && !(given[i].t_s > given[i - 1].t_s)) motion.Fail(list[i], "keyframe times must increase");
    PoseKeyframe key;
    key.t_s = given[i].t_s;
    key.position_m = pose0.translation() + given[i].offset_m;
    key.orientation = Eigen::Quaterniond(pose0.linear() * RotationFromRpyDeg(given[i].rpy_deg));
    keys.push_back(key);
  }
  return keys;
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
  config::YamlReadArchive a(&r);
  ShapeKind kind = ShapeKind::kPlane;
  a.Visit(Field("shape", &kind).Required());
  RigidObject obj;
  obj.name = config::NameOf(kind);
  a.Visit(Field("name", &obj.name));
  obj.shape = ReadShape(a, kind);
  const Eigen::Isometry3d pose0 = ReadInitialPose(a);
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
    keys = ReadKeyframes(motion, pose0);
  } else {
    PoseKeyframe key;
    key.position_m = pose0.translation();
    key.orientation = Eigen::Quaterniond(pose0.linear());
    keys.push_back(key);
  }
  VibrationKeys vibration;
  config::YamlReadArchive a(&motion);
  a.Visit(Field("vibration", &vibration));
  if (vibration.vibration.direction.norm() == 0)
    motion.Fail(motion.node()["vibration"]["direction"], "'direction' must be non-zero");
  return Trajectory(std::move(keys), vibration.vibration);
}

std::vector<RigidObject> ParseRigidObjects(config::MapReader& owner, const std::string& key) {
  const YAML::Node list = owner.Node(key);
  if (!list.IsSequence()) owner.Fail(list, "expected a list of objects");
  std::vector<RigidObject> out;
  for (const auto& item : list) {
    config::MapReader r(item, owner.file());
    out.push_back(ParseRigidObject(r));
    r.Finish();
  }
  return out;
}

}  // namespace sedbridge::geometry
