#include "sensors/simulated/simulated_sensor.h"

#include <gtest/gtest.h>
#include "tests/common/scratch_dir.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <initializer_list>

#include "common/config_error.h"
#include "common/resource_path.h"
#include "common/yaml_reader.h"
#include "sensors/scan_assembler.h"

namespace sedbridge::sensors {
namespace {

SensorProfile Shipped(const std::string& name) { return LoadSensorProfile(ResolveProfilePath(name)); }

// The first object of `list_yaml`, read as the `objects:` list of a file.
geometry::RigidObject Parse(const std::string& list_yaml) {
  auto doc = config::LoadYamlString("objects:\n" + list_yaml, "objects.yaml");
  config::MapReader owner(doc.root, doc.file);
  return geometry::ParseRigidObjects(owner, "objects").at(0);
}

// A scene file `name` with `yaml` must be refused with a ConfigError that mentions each of
// `mentions` (the key, the file:line); `what` says what would have been accepted.
void ExpectSceneRefused(const std::string& name, const std::string& yaml, const std::string& what,
                        std::initializer_list<const char*> mentions) {
  const std::string path = sedbridge::testing::ScratchDir() + "/" + name;
  std::ofstream(path) << yaml;
  try {
    LoadSimulatedSensorScene(path);
    FAIL() << what << " accepted";
  } catch (const config::ConfigError& e) {
    for (const char* m : mentions) EXPECT_NE(std::string(e.what()).find(m), std::string::npos) << e.what();
  }
}

// A flat plate 0.5 mm into the pad everywhere: every taxel reads E_eff * d / h.
TEST(SimulatedSensorTest, FlatPlateGivesTheWinklerPressureOnEveryTaxel) {
  SimulatedSensorConfig c;
  c.profile = Shipped("cyskin_16");
  c.pad.thickness_m = 2e-3;
  c.pad.youngs_modulus_Pa = 400e3;
  c.pad.poisson_ratio = 0.25;
  c.objects.push_back(Parse("- shape: plane\n  rpy_deg: [180, 0, 0]\n  position_mm: [0, 0, -0.5]\n"));
  SimulatedSensor sim(c);
  const double e_eff = 400e3 * 0.75 / (1.25 * 0.5);
  EXPECT_NEAR(c.pad.EffectiveModulus_Pa(), e_eff, 1e-6);
  const TaxelTractions t = sim.Evaluate(0);
  for (double p : t.pressure_Pa) EXPECT_NEAR(p, e_eff * 0.5e-3 / 2e-3, 1e-6);
}

TEST(SimulatedSensorTest, PenetrationIsMeasuredAlongThePadNormal) {
  // Grating ridge 2 mm wide pressed 1 mm deep: near the ridge wall the vertical depth is
  // still 1 mm (the nearest surface, the wall, is much closer).
  const auto grating = Parse(
      "- shape: grating\n  period_mm: 4\n  ridge_width_mm: 2\n  depth_mm: 1.5\n"
      "  rpy_deg: [180, 0, 0]\n  position_mm: [0, 0, -1]\n");
  const Eigen::Vector3d down(0, 0, -1);
  EXPECT_NEAR(PenetrationAlong(grating, {0.0, 0, 0}, down, 0), 1e-3, 2e-5);
  EXPECT_NEAR(PenetrationAlong(grating, {0.9e-3, 0, 0}, down, 0), 1e-3, 2e-5);
  EXPECT_EQ(PenetrationAlong(grating, {2.0e-3, 0, 0}, down, 0), 0.0);  // groove
}

TEST(SimulatedSensorTest, SpherePressIsSymmetricAndPeaksInTheMiddle) {
  SimulatedSensorConfig c;
  c.profile = Shipped("uskin_4x4");
  c.objects.push_back(Parse("- shape: sphere\n  radius_mm: 10\n  position_mm: [0, 0, 9]\n"));
  const TaxelTractions t = SimulatedSensor(c).Evaluate(0);
  // 4x4 grid: the four inner taxels 5, 6, 9, 10 carry the same, highest pressure.
  EXPECT_GT(t.pressure_Pa[5], 0);
  EXPECT_NEAR(t.pressure_Pa[5], t.pressure_Pa[10], 1e-6 * t.pressure_Pa[5]);
  EXPECT_NEAR(t.pressure_Pa[0], t.pressure_Pa[15], 1e-6 * t.pressure_Pa[5] + 1e-9);
  EXPECT_GT(t.pressure_Pa[5], t.pressure_Pa[0]);
  for (double s : t.shear_x_Pa) EXPECT_EQ(s, 0.0);  // no sliding, no friction
}

// `pad: {model: halfspace}`: a sphere pressed d deep carries Hertz's force 4/3 E* sqrt(R)
// d^1.5 (E* the profile's forward_model contact modulus), where the Winkler-pressure kernel
// pad carries E_eff / h * pi R d^2; both spread through the same kernels.
TEST(SimulatedSensorTest, HalfSpacePadCarriesHertzForce) {
  SimulatedSensorConfig c;
  c.profile = Shipped("uskin_4x4");
  ASSERT_TRUE(c.profile.has_forward_model);
  c.pad.mechanics = PadMechanics::kHalfSpace;
  const double R = 5e-3, depth = 0.3e-3;
  c.objects.push_back(Parse("- shape: sphere\n  radius_mm: 5\n  position_mm: [1, -1, 4.7]\n"));
  const SimulatedSensor sim(c);
  const double e_star = c.profile.forward_model.contact_modulus_kPa * 1e3;
  const double hertz_N = 4.0 / 3.0 * e_star * std::sqrt(R) * std::pow(depth, 1.5);
  const Eigen::Vector3d load = sim.TotalLoad_N(0);
  EXPECT_NEAR(load.z() / hertz_N, 1.0, 0.05);
  EXPECT_EQ(load.x(), 0.0);
  // The readings respond (the kernels), nearest taxels most.
  const TaxelTractions t = sim.Evaluate(0);
  double most = 0;
  for (double v : t.pressure_Pa) most = std::max(most, v);
  EXPECT_GT(most, 0);
  c.pad.mechanics = PadMechanics::kKernel;
  const double winkler_N = SimulatedSensor(c).TotalLoad_N(0).z();
  EXPECT_NEAR(winkler_N / (c.pad.EffectiveModulus_Pa() / c.pad.thickness_m * 3.14159265358979 * R * depth * depth), 1.0, 0.1);
  // Without a forward_model the scene is refused, naming the key.
  SimulatedSensorConfig bare = c;
  bare.pad.mechanics = PadMechanics::kHalfSpace;
  bare.profile.has_forward_model = false;
  EXPECT_THROW(SimulatedSensor{bare}, std::invalid_argument);
}

// `pad: {model: layer}`: under a flat much wider than the layer each column is compressed
// with its sides held (p = E_oed d / h away from the pad's edges, Winkler's law, as the
// rig's flats read), where the half-space pad loads the pad's edges most; a sphere whose
// contact is small against the layer carries nearly the half-space's (Hertz's) force.
TEST(SimulatedSensorTest, LayerPadIsAConfinedColumnUnderAFlatAndHertzUnderASmallSphere) {
  SimulatedSensorConfig c;
  c.profile = Shipped("uskin_4x4");
  c.pad.mechanics = PadMechanics::kLayer;
  c.pad.thickness_m = 2.5e-3;
  c.pad.youngs_modulus_Pa = 230e3;
  c.pad.poisson_ratio = 0.2;
  const double depth = 0.03e-3, nu = 0.2, e = 230e3;
  c.objects.push_back(Parse("- shape: plane\n  rpy_deg: [180, 0, 0]\n  position_mm: [0, 0, -0.03]\n"));
  auto pressure_at = [](const SimulatedSensor& sim, double x_mm, double y_mm) {
    std::vector<SurfaceLoad> loads;
    sim.PadLoads(0, &loads);
    const TactileForwardModel& model = *sim.forward_model();
    const double cell_m2 = std::pow(model.cell_size_mm() * 1e-3, 2);
    for (const SurfaceLoad& l : loads)
      if ((model.CellCentre_mm(l.cell) - Eigen::Vector2d(x_mm, y_mm)).norm() < 0.6 * model.cell_size_mm())
        return l.normal_N / cell_m2;
    return 0.0;
  };
  const SimulatedSensor layer(c);
  const double e_oed = e * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  EXPECT_NEAR(pressure_at(layer, 0, 0) / (e_oed * depth / c.pad.thickness_m), 1.0, 0.05);
  EXPECT_NEAR(pressure_at(layer, 5, 0) / pressure_at(layer, 0, 0), 1.0, 0.05);
  c.pad.mechanics = PadMechanics::kHalfSpace;  // E* = the forward model's
  const SimulatedSensor half_space(c);
  EXPECT_GT(pressure_at(half_space, 9.5, 0), 2 * pressure_at(half_space, 0, 0));
  // A 5 mm sphere 0.05 mm deep (Hertz contact radius 0.5 mm, a fifth of the layer): a bit
  // more force than the half-space of the same E* on the same grid (the base props it up;
  // ElasticPadContact's tests check the limits), far from the flat's confined columns.
  c.pad.mechanics = PadMechanics::kLayer;
  c.objects = {Parse("- shape: sphere\n  radius_mm: 5\n  position_mm: [0, 0, 4.95]\n")};
  const double layer_N = SimulatedSensor(c).TotalLoad_N(0).z();
  c.pad.mechanics = PadMechanics::kHalfSpace;
  c.profile.forward_model.contact_modulus_kPa = e / (1 - nu * nu) * 1e-3;
  const double half_space_N = SimulatedSensor(c).TotalLoad_N(0).z();
  EXPECT_GT(layer_N, 1.05 * half_space_N);
  EXPECT_LT(layer_N, 1.4 * half_space_N);
}

TEST(SimulatedSensorTest, SlidingWithFrictionGivesShearAlongTheMotion) {
  SimulatedSensorConfig c;
  c.profile = Shipped("uskin_4x4");
  c.pad.friction_coefficient = 0.5;
  c.objects.push_back(Parse(
      "- shape: plane\n  rpy_deg: [180, 0, 0]\n  position_mm: [0, 0, -0.3]\n"
      "  motion:\n    keyframes: [{t_s: 0, offset_mm: [0, 0, 0]}, {t_s: 1, offset_mm: [0, 5, 0]}]\n"));
  const TaxelTractions t = SimulatedSensor(c).Evaluate(0.5);
  EXPECT_NEAR(t.shear_y_Pa[3], 0.5 * t.pressure_Pa[3], 1e-6 * t.pressure_Pa[3]);
  EXPECT_NEAR(t.shear_x_Pa[3], 0.0, 1e-6 * t.pressure_Pa[3]);
}

// Simulation -> CAN frames -> scan assembler gives back the simulated pressure to within
// one count of quantisation, for every shipped profile.
class SimulatedPipelineTest : public ::testing::TestWithParam<std::string> {};

TEST_P(SimulatedPipelineTest, DecodedPressureMatchesTheSimulation) {
  SimulatedSensorConfig c;
  c.profile = Shipped(GetParam());
  c.duration_s = 0.2;
  c.objects.push_back(Parse("- shape: sphere\n  radius_mm: 12\n  position_mm: [0, 0, 11.2]\n"));
  SimulatedSensor sim(c);
  ScanAssembler assembler(c.profile);
  std::vector<Scan> scans;
  std::vector<Frame> frames;
  for (int64_t k = 0; k < sim.scan_count(); ++k) {
    frames.clear();
    sim.ScanFrames(k, &frames);
    for (const Frame& f : frames) assembler.Push(f, &scans);
  }
  ASSERT_EQ(static_cast<int64_t>(scans.size()), sim.scan_count());
  const TaxelTractions truth = sim.Evaluate(sim.ScanTime_s(3));
  const Scan& s = scans[3];
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(s.ValidCount(), c.profile.taxel_count);
  const double one_count_Pa =
      c.profile.calibration.scale_per_count[c.profile.NormalAxis()] *
      (c.profile.calibration.unit == CalibrationUnit::kKiloPascal ? 1e3
       : c.profile.calibration.unit == CalibrationUnit::kNewton ? 1.0 / (c.profile.taxel_area_mm2() * 1e-6)
                                                                 : 1.0);
  double max_pressure = 0;
  for (int i = 0; i < c.profile.taxel_count; ++i) {
    EXPECT_NEAR(s.pressure_Pa[i], truth.pressure_Pa[i], 0.51 * one_count_Pa) << "taxel " << i;
    max_pressure = std::max(max_pressure, s.pressure_Pa[i]);
  }
  EXPECT_GT(max_pressure, 20e3);  // the sphere really pressed
  EXPECT_EQ(assembler.counters().rejected(), 0);
}

INSTANTIATE_TEST_SUITE_P(Shipped, SimulatedPipelineTest,
                         ::testing::Values("uskin_4x4", "cyskin_16", "barrett_bh8_pad"));

TEST(SimulatedSensorTest, SameSeedSameFramesAndFaultsShowUpInTheCounters) {
  SimulatedSensorConfig c = LoadSimulatedSensorScene(
      config::ResolveResource("config/scenes/sensor_sphere_press.yaml"), "cyskin_16");
  c.noise.dropout_probability = 0.05;
  c.noise.bit_error_probability = 0.001;
  c.noise.seed = 99;
  auto run = [&](SimulatedSensorConfig cfg) {
    SimulatedSensorSource source(cfg);
    std::vector<Frame> all;
    while (auto f = source.Next(0)) all.push_back(*f);
    return all;
  };
  const auto a = run(c), b = run(c);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(a[i].SamePayload(b[i]) && a[i].utime == b[i].utime);
  c.noise.seed = 100;
  const auto other = run(c);
  bool differs = other.size() != a.size();
  for (size_t i = 0; !differs && i < a.size(); ++i) differs = !a[i].SamePayload(other[i]);
  EXPECT_TRUE(differs);

  // 2 s at 250 scans/s, 4 frames each, about 5% dropped.
  const int64_t sent = 500 * 4;
  EXPECT_LT(static_cast<int64_t>(a.size()), sent);
  EXPECT_GT(static_cast<int64_t>(a.size()), sent * 90 / 100);
  ScanAssembler assembler(c.profile);
  std::vector<Scan> scans;
  for (const Frame& f : a) assembler.Push(f, &scans);
  assembler.Flush(&scans);
  EXPECT_GT(assembler.counters().scans_partial, 0);
  EXPECT_GT(assembler.counters().missing_frames, 0);
}

TEST(SimulatedSensorTest, ShippedScenesLoadAndUnknownKeysAreErrors) {
  for (const char* scene : {"sensor_sphere_press", "sensor_edge_slide", "sensor_grating_press"}) {
    const auto c = LoadSimulatedSensorScene(config::ResolveResource(std::string("config/scenes/") + scene + ".yaml"));
    EXPECT_FALSE(c.objects.empty()) << scene;
    EXPECT_GT(SimulatedSensor(c).scan_count(), 10) << scene;
  }
  ExpectSceneRefused("bad_sensor_scene.yaml", "sensor:\n  profile: cyskin_16\n  pad: {thicknes_mm: 2}\nobjects: []\n",
                     "a typo", {"thicknes_mm"});
}

// `pad: {model: layer}` from a scene file: the rig's elastomer keys, a sphere pressing, and
// a profile without a forward_model refused naming the key.
TEST(SimulatedSensorScene, LayerPadLoadsAndPresses) {
  const std::string path = sedbridge::testing::ScratchDir() + "/layer_scene.yaml";
  std::ofstream(path) << "sensor:\n  profile: uskin_4x4\n  duration_s: 0.1\n"
                         "  pad: {model: layer, thickness_mm: 2.5, youngs_modulus_kPa: 230, poisson_ratio: 0.2}\n"
                         "objects:\n  - {shape: sphere, radius_mm: 5, position_mm: [0, 0, 4.6]}\n";
  const SimulatedSensorConfig c = LoadSimulatedSensorScene(path);
  EXPECT_EQ(c.pad.mechanics, PadMechanics::kLayer);
  EXPECT_DOUBLE_EQ(c.pad.thickness_m, 2.5e-3);
  const SimulatedSensor sim(c);
  EXPECT_GT(sim.TotalLoad_N(0).z(), 0.1);
  const TaxelTractions t = sim.Evaluate(0);
  EXPECT_GT(*std::max_element(t.pressure_Pa.begin(), t.pressure_Pa.end()), 0.0);
  ExpectSceneRefused("layer_scene_bare.yaml", "sensor:\n  profile: cyskin_16\n  pad: {model: layer}\nobjects: []\n",
                     "a layer pad without a forward model", {"model: layer", ":3:"});
}

TEST(SimulatedSensorScene, DurationIsBounded) {
  ExpectSceneRefused("long_scene.yaml", "sensor: {profile: uskin_4x4, duration_s: 2.0e9}\nobjects: []\n",
                     "a 2e9 s scene", {"duration_s", ":1:"});
}

}  // namespace
}  // namespace sedbridge::sensors
