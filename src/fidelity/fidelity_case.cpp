#include "fidelity/fidelity_case.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include "bridge/contact_fe_step.h"
#include "common/yaml_reader.h"
#include "sensors/scan_assembler.h"
#include "sensors/simulated/pad_rig_check.h"
#include "sensors/simulated/primitive_object.h"
#include "sensors/simulated/simulated_sensor.h"

namespace sedbridge::fidelity {
namespace {

// Synthetic press timing [s]: approach, ramp down, hold, release.
constexpr double kRampStart_s = 0.2, kRampEnd_s = 0.7, kHoldEnd_s = 0.95, kEnd_s = 1.25;
constexpr double kLift_mm = 0.3;  // objects start this far above the pad
// Flat faces' depths into the layer pad [mm]: about the rig punches' 0.5-1 N.
constexpr double kFacePunchDepth_mm = 0.55, kFaceRoundDepth_mm = 0.4, kFaceBarDepth_mm = 0.4;

struct SyntheticSpec {
  std::string name, label;
  std::string objects_yaml;  // objects at t = 0 (lowest point kLift_mm above the pad), no motion
  double depth_mm;           // penetration into the pad at the hold
  double slide_mm = 0;       // lateral travel during the hold (sliding case), along slide_yaw_deg
  double friction = 0;
  bool primitive = false;
  sensors::ContactPrimitive truth;  // shape, x, y, radius, yaw (force filled later)
  // The objects the truth presses on the leader, if not objects_yaml: a rod or sphere
  // thinner than the leader holds, at the leader's minimum radius (as the rig presses' truths
  // and the bridge press it: contact_object.h).
  std::string leader_objects_yaml;
  double slide_yaw_deg = 0;  // the slide's direction in the pad frame (0: +x)
};

std::string Motion(double depth_mm, double slide_mm, double slide_yaw_deg) {
  const double slide_x_mm = slide_mm * std::cos(slide_yaw_deg * M_PI / 180);
  const double slide_y_mm = slide_mm * std::sin(slide_yaw_deg * M_PI / 180);
  char m[512];
  std::snprintf(m, sizeof m,
                "motion: {keyframes: [{t_s: 0, offset_mm: [0, 0, 0]}, {t_s: %g, offset_mm: [0, 0, 0]}, "
                "{t_s: %g, offset_mm: [0, 0, %g]}, {t_s: %g, offset_mm: [%g, %g, %g]}, "
                "{t_s: %g, offset_mm: [%g, %g, 0]}]}",
                kRampStart_s, kRampEnd_s, -depth_mm, kHoldEnd_s, slide_x_mm, slide_y_mm, -depth_mm, kEnd_s, slide_x_mm,
                slide_y_mm);
  return m;
}

sensors::ContactPrimitive Primitive(sensors::ContactShape s, double x, double y, double r, double yaw = 0) {
  sensors::ContactPrimitive p;
  p.shape = s;
  p.x_mm = x;
  p.y_mm = y;
  p.radius_mm = r;
  p.yaw_deg = yaw;
  return p;
}

std::string SphereYaml(double r, double x, double y) {
  char yaml[256];
  std::snprintf(yaml, sizeof yaml, "{shape: sphere, radius_mm: %g, position_mm: [%g, %g, %g]", r, x, y, r + kLift_mm);
  return yaml;
}

// A rod across the pad (40 mm), or a finite one of length_mm centred on (x, y).
std::string RodYaml(double r, double yaw, double x, double y, double length_mm = 40) {
  char yaml[256];
  std::snprintf(yaml, sizeof yaml,
                "{shape: cylinder, radius_mm: %g, length_mm: %g, position_mm: [%g, %g, %g], rpy_deg: [0, 0, %g]", r,
                length_mm, x, y, r + kLift_mm, yaw);
  return yaml;
}

SyntheticSpec SphereSpec(const std::string& name, double r, double x, double y, double d) {
  char label[64];
  std::snprintf(label, sizeof label, "sphere R%g (%g, %g)", r, x, y);
  SyntheticSpec spec{name, label, SphereYaml(r, x, y), d, 0, 0, true, Primitive(sensors::ContactShape::kSphere, x, y, r), {}};
  if (r < contact::kLeaderMinSphereRadius_mm)
    spec.leader_objects_yaml = SphereYaml(contact::kLeaderMinSphereRadius_mm, x, y);
  return spec;
}

// A stroke: `spec`, a sphere placed at the slide's start, slides kStroke_mm along yaw_deg
// during the hold with `friction`; its truth is the mid-slide point.
constexpr double kStroke_mm = 3;
void MakeStroke(SyntheticSpec& spec, double yaw_deg, double friction, double mid_x_mm, double mid_y_mm) {
  spec.slide_mm = kStroke_mm;
  spec.slide_yaw_deg = yaw_deg;
  spec.friction = friction;
  spec.truth.x_mm = mid_x_mm;  // mid-slide, as sliding_sphere's (the table's position error)
  spec.truth.y_mm = mid_y_mm;
  char slide[64];
  std::snprintf(slide, sizeof slide, " sliding %g mm at %g deg (mu %g)", kStroke_mm, yaw_deg, friction);
  spec.label += slide;
}

SyntheticSpec RodSpec(const std::string& name, double r, double yaw, double x, double y, double d,
                      double length_mm = 40) {
  char label[96];
  if (length_mm < 40)
    std::snprintf(label, sizeof label, "rod R%g L%g yaw %g (%g, %g)", r, length_mm, yaw, x, y);
  else
    std::snprintf(label, sizeof label, "rod R%g yaw %g (%g, %g)", r, yaw, x, y);
  SyntheticSpec spec{name, label, RodYaml(r, yaw, x, y, length_mm), d, 0, 0, true,
                     Primitive(sensors::ContactShape::kCylinder, x, y, r, yaw), {}};
  if (length_mm < 40) spec.truth.length_mm = length_mm;
  if (r < contact::kLeaderMinRodRadius_mm)
    spec.leader_objects_yaml = RodYaml(contact::kLeaderMinRodRadius_mm, yaw, x, y, length_mm);
  return spec;
}

// A flat-faced punch kPunchHeight_mm tall standing on its face centred on (x, y), as a scene
// presses one: rectangular (half sizes a x b, turned by yaw; a box with the leader's punch
// rounding, sensors::kPunchRounding_mm) or round (a = its radius; a capped cylinder, its rim
// sharp). The truth is the punch primitive (kPunch with its half sizes, kRoundPunch with
// radius_mm), pressed on the leader as these objects.
SyntheticSpec PunchSpec(const std::string& name, bool round, double a, double b, double yaw, double x, double y,
                        double d) {
  constexpr double h = sensors::kPunchHeight_mm;
  char label[96], yaml[320];
  sensors::ContactPrimitive truth = Primitive(round ? sensors::ContactShape::kRoundPunch : sensors::ContactShape::kPunch,
                                              x, y, round ? a : 0, round ? 0 : yaw);
  if (round) {
    std::snprintf(label, sizeof label, "round punch R%g (%g, %g)", a, x, y);
    std::snprintf(yaml, sizeof yaml,
                  "{shape: cylinder, radius_mm: %g, length_mm: %g, position_mm: [%g, %g, %g], rpy_deg: [0, 90, 0]", a, h,
                  x, y, 0.5 * h + kLift_mm);
  } else {
    std::snprintf(label, sizeof label, "%s %gx%g yaw %g (%g, %g)", std::max(a, b) >= 3 * std::min(a, b) ? "bar" : "punch",
                  2 * a, 2 * b, yaw, x, y);
    std::snprintf(yaml, sizeof yaml,
                  "{shape: box, size_mm: [%g, %g, %g], rounding_mm: %g, position_mm: [%g, %g, %g], rpy_deg: [0, 0, %g]",
                  2 * a, 2 * b, h, std::min(sensors::kPunchRounding_mm, std::min(a, b)), x, y, 0.5 * h + kLift_mm, yaw);
    truth.half_size_mm[0] = a;
    truth.half_size_mm[1] = b;
  }
  return {name, label, yaml, d, 0, 0, true, truth, {}};
}

SyntheticSpec FlatSpec(const std::string& name, double d) {
  return {name, "flat", "{shape: plane, rpy_deg: [180, 0, 0], position_mm: [0, 0, 0.3]", d, 0, 0, true,
          Primitive(sensors::ContactShape::kFlat, 0, 0, 0), {}};
}

std::vector<SyntheticSpec> Specs() {
  using sensors::ContactShape;
  std::vector<SyntheticSpec> s;
  auto sphere = [&](double r, double x, double y, double d) {
    char name[64];
    std::snprintf(name, sizeof name, "sphere_r%g_%g_%g", r, x, y);
    s.push_back(SphereSpec(name, r, x, y, d));
  };
  auto rod = [&](double r, double yaw, double x, double y, double d) {
    char name[64];
    std::snprintf(name, sizeof name, "rod_r%g_yaw%g", r, yaw);
    s.push_back(RodSpec(name, r, yaw, x, y, d));
  };
  sphere(2, 3, -2, 0.8);
  sphere(5, -1, 1, 0.5);
  sphere(10, 2, 3, 0.4);
  sphere(15, -2, -2, 0.35);
  sphere(4, 5.5, -5.5, 0.5);
  rod(0.5, 0, 0, 1, 0.3);
  rod(1, 30, 1, -1, 0.25);
  rod(3, 75, -1, 0, 0.2);
  s.push_back(FlatSpec("flat", 0.025));
  // A 10 mm cube with an edge (along x) or a corner pointing into the pad.
  s.push_back({"box_edge", "box edge along x (0, 0)",
               "{shape: box, size_mm: [10, 10, 10], rpy_deg: [45, 0, 0], position_mm: [0, 0, 7.371]", 0.3, 0, 0, false, {}, {}});
  s.push_back({"box_corner", "box corner (1, -1)",
               "{shape: box, size_mm: [10, 10, 10], rpy_deg: [45, 35.264, 0], position_mm: [1, -1, 8.960]", 1.0, 0, 0, false, {}, {}});
  // Two contacts at once: objects_yaml holds two entries.
  s.push_back({"two_spheres", "two spheres R3 (-4, -3) and (4, 3)",
               "{shape: sphere, radius_mm: 3, position_mm: [-4, -3, 3.3]|{shape: sphere, radius_mm: 3, position_mm: [4, 3, 3.3]",
               0.5, 0, 0, false, {}, {}});
  // Stroking: a sphere pressed, then slid 4 mm along +x with friction 0.4.
  s.push_back({"sliding_sphere", "sphere R5 sliding +x 4 mm (mu 0.4)",
               "{shape: sphere, radius_mm: 5, position_mm: [-2, 0, 5.3]", 0.5, 4.0, 0.4, true,
               Primitive(ContactShape::kSphere, 0, 0, 5), {}});
  // Flat faces (after the rest, whose rows they leave as they were): a rectangular punch, a
  // round one and a bar, each about 1 N on the layer pad as the rig's punches.
  s.push_back(PunchSpec("punch_4x2_yaw30", false, 2.0, 1.0, 30, 1, -1, kFacePunchDepth_mm));
  s.push_back(PunchSpec("round_punch_r2", true, 2.0, 2.0, 0, -1, 1.5, kFaceRoundDepth_mm));
  s.push_back(PunchSpec("bar_8x1.5_yaw-20", false, 4.0, 0.75, -20, 0.5, 0.5, kFaceBarDepth_mm));
  return s;
}

// SplitMix64 of (seed, index): well-separated streams for neighbouring seeds and indices.
uint64_t CaseNoiseSeed(uint64_t seed, size_t index) {
  uint64_t z = seed * 0x9E3779B97F4A7C15ull + (uint64_t(index) + 1) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// The bounds of one RandomRanges (see there).
struct DrawBounds {
  double sphere_r_mm[2], sphere_xy_mm, sphere_depth_mm[2];
  double rod_r_mm[2], rod_xy_mm, rod_depth_mm[2];
  double flat_depth_mm[2];
};

DrawBounds BoundsOf(RandomRanges ranges) {
  if (ranges == RandomRanges::kWide)
    return {{1.5, 20.0}, 7.0, {0.15, 1.1}, {0.4, 4.0}, 6.0, {0.05, 0.45}, {0.01, 0.08}};
  return {{2.0, 15.0}, 6.0, {0.3, 0.8}, {0.5, 3.0}, 4.0, {0.1, 0.3}, {0.02, 0.05}};
}

// Presses drawn at random: spheres, rods, flats and strokes like the rig's, at sizes,
// places, yaws and depths it did not use (kRig: depths giving about the rig's 0.3-1.5 N on
// the rig-fitted layer pad). Both ranges draw the same sequence, so a seed's presses are the
// same kinds in the same order, only scaled to the other bounds.
std::vector<SyntheticSpec> RandomSpecs(int count, uint64_t seed, RandomRanges ranges) {
  const DrawBounds bounds = BoundsOf(ranges);
  std::mt19937_64 rng(seed);
  auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  auto round2 = [](double v) { return std::round(v * 100) / 100; };  // names and labels stay short
  std::vector<SyntheticSpec> s;
  for (int i = 0; i < count; ++i) {
    char name[64];
    const double kind = uniform(0, 1);
    if (kind < 0.45) {
      const double r = round2(std::exp(uniform(std::log(bounds.sphere_r_mm[0]), std::log(bounds.sphere_r_mm[1]))));
      std::snprintf(name, sizeof name, "random_%02d_sphere", i);
      s.push_back(SphereSpec(name, r, round2(uniform(-bounds.sphere_xy_mm, bounds.sphere_xy_mm)),
                             round2(uniform(-bounds.sphere_xy_mm, bounds.sphere_xy_mm)),
                             round2(uniform(bounds.sphere_depth_mm[0], bounds.sphere_depth_mm[1]))));
    } else if (kind < 0.8) {
      const double r = round2(std::exp(uniform(std::log(bounds.rod_r_mm[0]), std::log(bounds.rod_r_mm[1]))));
      std::snprintf(name, sizeof name, "random_%02d_rod", i);
      s.push_back(RodSpec(name, r, std::round(uniform(0, 180)), round2(uniform(-bounds.rod_xy_mm, bounds.rod_xy_mm)),
                          round2(uniform(-bounds.rod_xy_mm, bounds.rod_xy_mm)),
                          round2(uniform(bounds.rod_depth_mm[0], bounds.rod_depth_mm[1]))));
    } else if (kind < 0.88) {
      std::snprintf(name, sizeof name, "random_%02d_flat", i);
      s.push_back(FlatSpec(name, round2(uniform(bounds.flat_depth_mm[0], bounds.flat_depth_mm[1]) * 1e3) * 1e-3));
    } else {
      std::snprintf(name, sizeof name, "random_%02d_stroke", i);
      // Drawn in the order the former one-call draw took them (g++ evaluates arguments right
      // to left), so seeds keep their strokes' spheres, places and depths.
      const double d = round2(uniform(0.4, 0.7)), y = round2(uniform(-4, 4));
      const double start_x = round2(uniform(-4, 0)), r = round2(uniform(4, 10));
      // Mid-slide where a +x stroke from (start_x, y) has it; the direction any, from a
      // stream of its own (the rig strokes along +x and -y; the main stream, and so every
      // other drawn press, stays as it was when strokes went along +x only).
      std::mt19937_64 direction_rng(CaseNoiseSeed(seed ^ 0x5354524F4B45ull, size_t(i)));
      const double yaw_deg = std::round(std::uniform_real_distribution<double>(0, 360)(direction_rng));
      const double c = std::cos(yaw_deg * M_PI / 180), sn = std::sin(yaw_deg * M_PI / 180);
      const double half_mm = kStroke_mm / 2, mid_x = start_x + half_mm;
      SyntheticSpec spec = SphereSpec(name, r, round2(mid_x - half_mm * c), round2(y - half_mm * sn), d);
      MakeStroke(spec, yaw_deg, 0.3, mid_x, y);
      s.push_back(spec);
    }
  }
  return s;
}

// Flat faces drawn at random (SyntheticFidelityCases' random_faces): rectangular punches,
// round ones and bars in turn, at any yaw within 4 mm of the pad centre, from a stream of
// their own (seed's drawn presses stay as they are); named from `first` on.
std::vector<SyntheticSpec> RandomFaceSpecs(int count, uint64_t seed, int first) {
  std::mt19937_64 rng(CaseNoiseSeed(seed ^ 0x4641434553ull, 0));  // "FACES"
  auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  auto round2 = [](double v) { return std::round(v * 100) / 100; };
  std::vector<SyntheticSpec> s;
  for (int i = 0; i < count; ++i) {
    char name[64];
    const int kind = i % 3;
    const double x = round2(uniform(-4, 4)), y = round2(uniform(-4, 4)), yaw = std::round(uniform(-90, 90));
    const double depth = round2(uniform(0.8, 1.25) * (kind == 1 ? kFaceRoundDepth_mm : kind == 2 ? kFaceBarDepth_mm : kFacePunchDepth_mm) * 100) / 100;
    if (kind == 0) {  // a punch 1.5-6 mm a side, up to 2:1
      const double a = round2(uniform(0.75, 3.0)), b = round2(a * uniform(0.5, 1.0));
      std::snprintf(name, sizeof name, "random_%02d_punch", first + i);
      s.push_back(PunchSpec(name, false, a, b, yaw, x, y, depth));
    } else if (kind == 1) {  // a round punch 1-3.5 mm in radius
      std::snprintf(name, sizeof name, "random_%02d_round_punch", first + i);
      s.push_back(PunchSpec(name, true, round2(uniform(1.0, 3.5)), 0, 0, x, y, depth));
    } else {  // a bar 5-10 mm long, 1-2 mm wide
      std::snprintf(name, sizeof name, "random_%02d_bar", first + i);
      s.push_back(PunchSpec(name, false, round2(uniform(2.5, 5.0)), round2(uniform(0.5, 1.0)), yaw, x, y, depth));
    }
  }
  return s;
}

}  // namespace

std::vector<geometry::RigidObject> FidelityCase::ObjectsAt(size_t k) const {
  std::vector<geometry::RigidObject> out;
  for (const auto& o : objects) {
    Eigen::Isometry3d pose = o.trajectory.Pose(t_s[k]);
    pose.translation().z() = o.trajectory.Pose(0.0).translation().z();
    geometry::RigidObject p = o;
    p.trajectory = geometry::Trajectory(pose);
    out.push_back(p);
  }
  return out;
}

namespace {

// One object of a rig press in words: "sphere R5 (0, 0)", "rod R1 yaw 90 (0, -2)" (a finite
// rod: "rod R1.5 L6 yaw 120 (-2, 0)"), "flat", "punch 3x3 yaw 0 (0, 0)" (its full sizes).
std::string LabelOf(const sensors::PressedObject& object) {
  const sensors::ContactPrimitive& o = object.primitive;
  char label[96];
  switch (object.shape) {
    case sensors::PressShape::kFlat:
      return "flat";
    case sensors::PressShape::kSphere:
      std::snprintf(label, sizeof label, "sphere R%g (%g, %g)", o.radius_mm, o.x_mm, o.y_mm);
      return label;
    case sensors::PressShape::kCylinder:
      if (o.length_mm > 0)
        std::snprintf(label, sizeof label, "rod R%g L%g yaw %g (%g, %g)", o.radius_mm, o.length_mm, o.yaw_deg, o.x_mm,
                      o.y_mm);
      else
        std::snprintf(label, sizeof label, "rod R%g yaw %g (%g, %g)", o.radius_mm, o.yaw_deg, o.x_mm, o.y_mm);
      return label;
    case sensors::PressShape::kPunch:
      std::snprintf(label, sizeof label, "punch %gx%g yaw %g (%g, %g)", 2 * object.half_size_mm[0],
                    2 * object.half_size_mm[1], o.yaw_deg, o.x_mm, o.y_mm);
      return label;
    case sensors::PressShape::kPair:
      break;
  }
  return "?";
}

// The object as the leader is pressed with it: a primitive as the bridge presses it
// (contact::ToRigidObject: a finite rod a capped cylinder of its length), a punch as the
// bridge presses a reconstructed one (sensors::RigidObjectOf: a box with rounded edges).
geometry::RigidObject LeaderObjectOf(const sensors::PressedObject& object) {
  if (object.shape != sensors::PressShape::kPunch) return contact::ToRigidObject(object.primitive);
  sensors::ContactPrimitive punch = object.primitive;
  punch.shape = sensors::ContactShape::kPunch;
  punch.half_size_mm[0] = object.half_size_mm[0];
  punch.half_size_mm[1] = object.half_size_mm[1];
  return contact::ToRigidObject(punch);
}

}  // namespace

FidelityCase FromCalibrationPress(const sensors::CalibrationPress& press) {
  FidelityCase c;
  c.name = press.name.substr(0, press.name.rfind('.'));
  if (press.is_primitive()) {
    sensors::PressedObject as_given;  // the press's own primitive (a caller may have changed it)
    as_given.shape = press.shape;
    as_given.primitive = press.object;
    c.label = LabelOf(as_given);
  } else if (press.shape == sensors::PressShape::kPair) {
    // Both objects pressed together, as one rigid pair, to the press's force: the leader's
    // press takes one force for all its objects, so the leader's mechanics share it out, not
    // the rig's split (which the label gives).
    c.label = "pair:";
    for (const sensors::PressedObject& o : press.objects) {
      char share[32];
      std::snprintf(share, sizeof share, " %.0f%%", 100 * o.share);
      c.label += (c.label.size() > 5 ? ", " : " ") + LabelOf(o) + share;
    }
  } else {
    c.label = LabelOf(press.objects[0]);
  }
  c.scans = press.scans;
  c.t_s = press.t_s;
  c.has_primitive = press.is_primitive();
  if (c.has_primitive) {  // the press's primitive, as fit-sensor and the reconstruction know it
    for (double t : press.t_s) {
      const sensors::ContactPrimitive at = press.ObjectAt(t);
      c.load_N.emplace_back(at.shear_x_N, at.shear_y_N, at.normal_force_N);
    }
    c.objects = {contact::ToRigidObject(press.object)};
    c.primitive = press.object;
    return c;
  }
  for (double t : press.t_s) {  // a punch's load, or both of a pair's
    const double f = press.protocol.LoadFraction(t);
    Eigen::Vector3d load = Eigen::Vector3d::Zero();
    for (const sensors::PressedObject& o : press.objects)
      load += f * Eigen::Vector3d(o.primitive.shear_x_N, o.primitive.shear_y_N, o.primitive.normal_force_N);
    c.load_N.push_back(load);
  }
  for (const sensors::PressedObject& o : press.objects) c.objects.push_back(LeaderObjectOf(o));
  return c;
}

namespace {

sensors::PadModel SimulatedPad(sensors::PadMechanics pad) {
  sensors::PadModel model;
  if (pad == sensors::PadMechanics::kLayer) model = sensors::RigFittedLayerPad();
  model.mechanics = pad;
  return model;
}

// Presses every spec into the simulated sensor. per_case_noise: each press its own noise
// stream (from `seed` and its index); else all share the stream `seed`.
std::vector<FidelityCase> Simulate(const std::vector<SyntheticSpec>& specs, const sensors::SensorProfile& profile,
                                   uint64_t seed, sensors::PadMechanics pad, bool per_case_noise) {
  std::vector<FidelityCase> cases;
  for (size_t index = 0; index < specs.size(); ++index) {
    const SyntheticSpec& spec = specs[index];
    sensors::SimulatedSensorConfig config;
    config.profile = profile;
    config.pad = SimulatedPad(pad);
    config.pad.friction_coefficient = spec.friction;
    config.noise.seed = per_case_noise ? CaseNoiseSeed(seed, index) : seed;
    config.noise.stddev_counts = 2;
    config.duration_s = kEnd_s + 0.1;
    auto parse_objects = [&](const std::string& objects_yaml) {
      std::string yaml = "objects: [";
      size_t start = 0;
      for (;;) {  // entries separated by '|'
        const size_t bar = objects_yaml.find('|', start);
        const std::string one = objects_yaml.substr(start, bar == std::string::npos ? std::string::npos : bar - start);
        yaml += one + ", " + Motion(spec.depth_mm + kLift_mm, spec.slide_mm, spec.slide_yaw_deg) + "}";
        if (bar == std::string::npos) break;
        yaml += ", ";
        start = bar + 1;
      }
      yaml += "]";
      const config::YamlDocument doc = config::LoadYamlString(yaml, "synthetic:" + spec.name);
      config::MapReader objects_owner(doc.root, doc.file);
      return geometry::ParseRigidObjects(objects_owner, "objects");
    };
    config.objects = parse_objects(spec.objects_yaml);
    FidelityCase c;
    c.name = spec.name;
    c.label = spec.label;
    c.objects = spec.leader_objects_yaml.empty() ? config.objects : parse_objects(spec.leader_objects_yaml);
    c.has_primitive = spec.primitive;
    c.primitive = spec.truth;
    sensors::SimulatedSensorSource source(config);
    sensors::ScanAssembler assembler(profile);
    while (auto f = source.Next(0)) assembler.Push(*f, &c.scans);
    assembler.Flush(&c.scans);
    const sensors::SimulatedSensor& sensor = source.sensor();
    for (const auto& s : c.scans) {
      // The scan's sample time (its frames follow it by a few 100 us).
      const double rate = profile.scan_rate_Hz;
      const double t = std::floor(1e-6 * static_cast<double>(s.utime - config.start_utime) * rate + 1e-6) / rate;
      c.t_s.push_back(t);
      c.load_N.push_back(sensor.TotalLoad_N(t));
    }
    cases.push_back(std::move(c));
  }
  return cases;
}

}  // namespace

const config::EnumNames<RandomRanges>& NamesOf(RandomRanges) {
  static const config::EnumNames<RandomRanges> names{{RandomRanges::kRig, "rig"}, {RandomRanges::kWide, "wide"}};
  return names;
}

std::vector<FidelityCase> SyntheticFidelityCases(const sensors::SensorProfile& profile, uint64_t seed,
                                                 sensors::PadMechanics pad, int random_count, RandomRanges ranges,
                                                 int random_faces) {
  // A drawn press gets its own noise stream: with one stream, every case saw the same noise
  // at the same scan, and N drawn presses were not N independent draws. The fixed set keeps
  // one stream, so its table compares with earlier runs.
  if (random_count <= 0 && random_faces <= 0) return Simulate(Specs(), profile, seed, pad, false);
  std::vector<SyntheticSpec> specs = RandomSpecs(random_count, seed, ranges);
  for (SyntheticSpec& face : RandomFaceSpecs(random_faces, seed, std::max(random_count, 0)))
    specs.push_back(std::move(face));
  return Simulate(specs, profile, seed, pad, true);
}

std::vector<FidelityCase> BeyondPrimitiveFidelityCases(const sensors::SensorProfile& profile, uint64_t seed,
                                                       sensors::PadMechanics pad) {
  std::vector<SyntheticSpec> s;
  // A grating: four bars 3 mm apart, each a rod R0.75 14 mm long (capped), across x.
  std::string grating;
  for (const double x : {-4.5, -1.5, 1.5, 4.5}) grating += (grating.empty() ? "" : "|") + RodYaml(0.75, 90, x, 0, 14);
  s.push_back({"grating", "grating: 4 bars R0.75 L14 3 mm apart", grating, 0.2, 0, 0, false, {}, {}});
  // A cross: two rods R1 10 mm long crossing at (0.5, -0.5) (the adequacy test's, moved).
  s.push_back({"cross", "cross: rods R1 L10 at 0 and 90 deg (0.5, -0.5)",
               RodYaml(1, 0, 0.5, -0.5, 10) + "|" + RodYaml(1, 90, 0.5, -0.5, 10), 0.25, 0, 0, false, {}, {}});
  // Three spheres R3 at once (the adequacy test's places).
  s.push_back({"three_spheres", "three spheres R3 (-5, -4), (5, -4), (0, 5)",
               SphereYaml(3, -5, -4) + "|" + SphereYaml(3, 5, -4) + "|" + SphereYaml(3, 0, 5), 0.4, 0, 0, false, {}, {}});
  // A ring of a punch's size: a torus is not a shape here; a box with a rounded 4 x 4 mm face
  // pressed slightly tilted (one edge first): neither a punch nor a rod.
  s.push_back({"tilted_block", "block 4 x 4 mm face, tilted 4 deg about y (0, 1)",
               "{shape: box, size_mm: [4, 4, 4], rounding_mm: 0.3, rpy_deg: [0, 4, 0], position_mm: [0, 1, 2.44]", 0.25,
               0, 0, false, {}, {}});
  return Simulate(s, profile, seed, pad, true);
}

std::vector<FidelityCase> CalibrationPressesOnSimulatedPad(const std::vector<sensors::CalibrationPress>& all_presses,
                                                           const sensors::SensorProfile& profile, uint64_t seed,
                                                           sensors::PadMechanics pad) {
  // The depth at which the pad carries each press's hold force, as fit-sensor --evaluate-pad
  // finds it.
  // Only what the simulated pad presses: primitives, not the rig's punches and pairs.
  const std::vector<sensors::CalibrationPress> presses = sensors::PrimitivePresses(all_presses);
  const std::vector<sensors::PadPressReport> depths = sensors::EvaluatePadOnPresses(presses, profile, SimulatedPad(pad));
  std::vector<SyntheticSpec> specs;
  for (size_t i = 0; i < presses.size(); ++i) {
    const sensors::ContactPrimitive& o = presses[i].object;
    if (!depths[i].reached) continue;
    const std::string name = presses[i].name.substr(0, presses[i].name.rfind('.'));
    const double depth_mm = depths[i].depth_mm;
    SyntheticSpec spec;
    if (o.shape == sensors::ContactShape::kFlat) {
      spec = FlatSpec(name, depth_mm);
    } else if (o.shape == sensors::ContactShape::kCylinder) {
      spec = RodSpec(name, o.radius_mm, o.yaw_deg, o.x_mm, o.y_mm, depth_mm, o.length_mm > 0 ? o.length_mm : 40);
    } else {
      const double traction = std::hypot(o.shear_x_N, o.shear_y_N) / std::max(o.normal_force_N, 1e-12);
      if (traction > 0) {
        // The rig's stroke holds a tangential load; the simulated pad makes one by sliding
        // with friction: along the load through the rig's place, friction = the load's
        // ratio to the normal force.
        const double yaw = std::atan2(o.shear_y_N, o.shear_x_N), half_mm = kStroke_mm / 2;
        spec = SphereSpec(name, o.radius_mm, o.x_mm - half_mm * std::cos(yaw), o.y_mm - half_mm * std::sin(yaw),
                          depth_mm);
        MakeStroke(spec, yaw * 180 / M_PI, traction, o.x_mm, o.y_mm);
      } else {
        spec = SphereSpec(name, o.radius_mm, o.x_mm, o.y_mm, depth_mm);
      }
    }
    specs.push_back(spec);
  }
  return Simulate(specs, profile, seed, pad, true);
}

}  // namespace sedbridge::fidelity
