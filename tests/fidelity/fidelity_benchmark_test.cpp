// The fidelity benchmark on calibration-rig presses of the uSkin-like sensor: the
// reconstructed contact meets the fidelity targets where the pressure map misses them.
#include "fidelity/fidelity_benchmark.h"

#include <gtest/gtest.h>

#include <cstdio>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "contact/contact_object.h"
#include "common/resource_path.h"
#include "common/yaml_reader.h"
#include "display/display_profile.h"
#include "fidelity/fidelity_case.h"
#include "sensors/tactile_model_fit.h"

namespace sedbridge::fidelity {
namespace {

using namespace sedbridge::bridge;  // the leader press, contact objects and configs the benchmark runs

// The uskin_4x4 rig presses and a benchmark on model B with the suction display.
struct RigBench {
  sensors::SensorProfile profile = sensors::LoadNamedSensorProfile("uskin_4x4");
  std::vector<sensors::CalibrationPress> presses =
      sensors::LoadCalibrationPresses(config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), profile);
  std::unique_ptr<FidelityBenchmark> bench = std::make_unique<FidelityBenchmark>(
      "B", profile, display::LoadNamedDisplayProfile("suction_4x4"), "");
};

// The 0.6 mm rod of press_16 has a truth with the leader's face contact (the default).
// With skin nodes only (`fidelity --node-contact`) its press depends on the path: pushed
// down step by step it passes between the nodes (no truth); under force control a few
// nodes hold it on their flanks (FingertipCompliance.FaceContactCatchesARodThinnerThanThe
// NodeSpacing), so node contact is not asserted here.
TEST(FidelityBenchmark, FaceContactGivesTheThinRodATruth) {
  const RigBench rig;
  FidelityMaps maps;
  const FidelityRow by_faces = rig.bench->Run(FromCalibrationPress(rig.presses[16]), &maps);
  EXPECT_TRUE(by_faces.truth_valid) << by_faces.truth_press;
}

TEST(FidelityBenchmark, RigPressesMeetTheTargetsWithReconstructedContact) {
  const RigBench rig;
  const auto& presses = rig.presses;
  FidelityBenchmark& bench = *rig.bench;
  // Spheres of 2.5, 5, 8 and 15 mm, a flat, and a stroke.
  for (int i : {1, 3, 6, 9, 17, 19}) {
    FidelityMaps maps;
    const FidelityRow r = bench.Run(FromCalibrationPress(presses[size_t(i)]), &maps);
    SCOPED_TRACE(r.name);
    EXPECT_TRUE(r.recon_ok);
    EXPECT_GT(r.recon_error.peak_ratio, 0.8);
    EXPECT_LT(r.recon_error.peak_ratio, 1.25);
    EXPECT_LT(r.recon_error.rel_l2, 0.25);
    EXPECT_LE(r.recon_error.peak_offset_mm, 1.0);
    // The pressure map delivers a small fraction of the peak.
    EXPECT_LT(r.map_error.peak_ratio, 0.5);
    EXPECT_GT(r.map_error.rel_l2, 0.5);
  }
}

}  // namespace
}  // namespace sedbridge::fidelity

namespace sedbridge::fidelity {
namespace {

// Rods of 0.6, 1 and 2.5 mm, pressed on the leader with face contact (contact::LeaderComplianceOptions):
// peak SED and L2 meet the targets on all five, and the peak offset on all but two, whose
// SED is a ridge along the rod: its maximum moves along it by a vertex spacing (about
// 1.5 mm) for a few percent of SED, so measured to the other field's peak region (within
// 5 % of its maximum) they agree too. The 0.6 mm rod (press_16) has a truth only with face
// contact: with node contact it passed between the skin nodes (patch_edge).
TEST(FidelityBenchmark, RigRodsMeetTheTargetsWithReconstructedContact) {
  const RigBench rig;
  const auto& presses = rig.presses;
  FidelityBenchmark& bench = *rig.bench;
  int within = 0;
  for (int i : {12, 13, 14, 15, 16}) {
    FidelityMaps maps;
    const FidelityRow r = bench.Run(FromCalibrationPress(presses[size_t(i)]), &maps);
    SCOPED_TRACE(r.name);
    EXPECT_TRUE(r.truth_valid) << r.truth_press;
    EXPECT_TRUE(r.recon_ok);
    EXPECT_GT(r.recon_error.peak_ratio, 0.8);
    EXPECT_LT(r.recon_error.peak_ratio, 1.25);
    EXPECT_LT(r.recon_error.rel_l2, 0.25);
    EXPECT_LE(r.recon_error.peak_region_offset_mm, r.recon_error.peak_offset_mm);
    EXPECT_LE(r.recon_error.peak_region_offset_mm, 1.0);
    within += WithinTargets(r.recon_error) ? 1 : 0;
  }
  EXPECT_GE(within, 3);
}

}  // namespace
}  // namespace sedbridge::fidelity

namespace sedbridge::fidelity {
namespace {

// press_11 (a 3.5 mm sphere at the pad's corner, 0.3 N): on the leader's pad the sphere cannot
// reach the measured force (patch_edge), so the case has no truth to score against; the
// benchmark says so instead of counting a hit or a miss. press_01 has one and meets the targets.
TEST(FidelityBenchmark, CaseWithoutAValidTruthIsFlaggedNotScored) {
  const RigBench rig;
  const auto& presses = rig.presses;
  FidelityBenchmark& bench = *rig.bench;
  FidelityMaps maps;
  const FidelityRow edge = bench.Run(FromCalibrationPress(presses[11]), &maps);
  EXPECT_FALSE(edge.truth_valid);
  EXPECT_EQ(edge.truth_press.rfind("patch_edge", 0), 0u) << edge.truth_press;
  const FidelityRow centre = bench.Run(FromCalibrationPress(presses[1]), &maps);
  EXPECT_TRUE(centre.truth_valid);
  EXPECT_EQ(centre.truth_press, "reached");
  EXPECT_TRUE(WithinTargets(centre.recon_error));
  EXPECT_FALSE(WithinTargets(centre.map_error));
}

// `sedbridge fidelity --config`: the judged bridge's fe.contact_tolerance reaches the
// reconstructed press (a loose 0.05 moves its SED), not the truth (the method's own
// tolerance); fe.two_contacts: false leaves the synthetic pair to single primitives.
TEST(FidelityBenchmark, BridgeConfigReachesTheReconstructedPress) {
  const RigBench rig;
  BridgeConfig loose = LoadBridgeConfig(DefaultBridgeConfigPath());
  loose.compliance_cache_dir = "";
  loose.contact_tolerance = 0.05;
  loose.two_contacts = false;
  FidelityBenchmark bench("B", rig.profile, display::LoadNamedDisplayProfile("suction_4x4"), loose);
  FidelityMaps by_default, by_loose;
  const FidelityRow a = rig.bench->Run(FromCalibrationPress(rig.presses[3]), &by_default);
  const FidelityRow b = bench.Run(FromCalibrationPress(rig.presses[3]), &by_loose);
  ASSERT_TRUE(a.recon_ok && b.recon_ok);
  EXPECT_EQ((by_default.truth - by_loose.truth).cwiseAbs().maxCoeff(), 0.0);
  const double moved = (by_default.recon - by_loose.recon).cwiseAbs().maxCoeff() / by_default.recon.maxCoeff();
  EXPECT_GT(moved, 1e-4);
  EXPECT_LT(moved, 0.1);
  const std::vector<FidelityCase> cases = SyntheticFidelityCases(rig.profile);
  const auto pair = std::find_if(cases.begin(), cases.end(), [](const FidelityCase& c) { return c.name == "two_spheres"; });
  ASSERT_NE(pair, cases.end());
  EXPECT_FALSE(bench.Run(*pair, &by_loose).recon_two_contacts);
}

// Two 3 mm spheres pressed at once on the simulated sensor (the synthetic set's two_spheres):
// one primitive cannot explain them (the pressure map took over: peak ratio 0.03, L2 0.95);
// the pair model finds both where they are, and the leader, pressed with both, gets most of
// the truth's peak at the right spots. The L2 target is not asserted: on the Winkler pad the
// radius read about 2x too large (its contact law against the model's Hertz).
TEST(FidelityBenchmark, TwoSpheresAreReconstructedAsAPair) {
  const RigBench rig;
  const std::vector<FidelityCase> cases = SyntheticFidelityCases(rig.profile);
  const auto it = std::find_if(cases.begin(), cases.end(), [](const FidelityCase& c) { return c.name == "two_spheres"; });
  ASSERT_NE(it, cases.end());
  FidelityMaps maps;
  const FidelityRow r = rig.bench->Run(*it, &maps);
  ASSERT_TRUE(r.truth_valid) << r.truth_press;
  ASSERT_TRUE(r.recon_ok) << r.recon_press;
  ASSERT_TRUE(r.recon_two_contacts);
  EXPECT_EQ(r.recon_press, "reached");
  // Both centres within 0.3 mm of (-4, -3) and (4, 3), in either order.
  const bool swapped = r.recon_object.x_mm > r.recon_second.x_mm;
  const auto& a = swapped ? r.recon_second : r.recon_object;
  const auto& b = swapped ? r.recon_object : r.recon_second;
  EXPECT_LT(std::hypot(a.x_mm + 4, a.y_mm + 3), 0.3);
  EXPECT_LT(std::hypot(b.x_mm - 4, b.y_mm - 3), 0.3);
  // Measured on the rig-fitted layer pad (the set's default) 0.85 / 0.11 / 1.3 mm; on the
  // Winkler pad 0.72 / 0.52 / 1.3 mm (map: 0.03 / 0.95 / 2.0).
  EXPECT_GT(r.recon_error.peak_ratio, 0.6);
  EXPECT_LT(r.recon_error.peak_ratio, 1.25);
  EXPECT_LT(r.recon_error.rel_l2, 0.65);
  EXPECT_LT(r.recon_error.rel_l2, r.map_error.rel_l2 - 0.3);
  EXPECT_LT(r.recon_error.peak_offset_mm, 2.0);
}

// The closest thing here to presses the sensor's users have not shown us: the forward model
// refitted from the generic start on 15 rig presses, the other six (spheres 2.5 / 8 / 15 /
// 6 mm, rods 2.5 / 0.6 mm) through the benchmark with it. Every model the reconstruction
// knows competes here, so this is where a new one must not steal a case: the finite rod took
// the 15 mm sphere (press_10) as a 4.9 mm rod of radius 11 mm, peak ratio 1.95, until rods
// shorter than their diameter were ruled out. Measured: 5 of 6 within all three by argmax
// (press_16's argmax is 1.9 mm along its ridge), 6 of 6 by peak region.
TEST(FidelityBenchmark, HeldOutPressesWithARefittedSensorModel) {
  RigBench rig;
  const std::vector<std::string> held = {"press_02.log", "press_07.log", "press_10.log",
                                         "press_14.log", "press_16.log", "press_20.log"};
  std::vector<sensors::CalibrationPress> fit_set, held_out;
  for (auto& p : rig.presses)
    if (p.name < "press_21.log")  // 00-20: the presses this test was measured on
      (std::find(held.begin(), held.end(), p.name) != held.end() ? held_out : fit_set).push_back(p);
  ASSERT_EQ(held_out.size(), 6u);
  // Through the YAML that `fit-sensor --out` writes (its printed digits), as a user gets it.
  const std::string yaml = sensors::TactileModelParamsYaml(
      sensors::FitTactileModel(fit_set, rig.profile, sensors::InitialTactileModelParams()).params, 0);
  const config::YamlDocument doc = config::LoadYamlString(yaml, "refitted.yaml");
  config::MapReader reader(doc.root, doc.file);
  sensors::SensorProfile refitted = rig.profile;
  refitted.forward_model = sensors::ParseTactileModelParams(reader);
  FidelityBenchmark bench("B", refitted, display::LoadNamedDisplayProfile("suction_4x4"), "");
  int by_argmax = 0, by_region = 0;
  for (const auto& press : held_out) {
    FidelityMaps maps;
    const FidelityRow r = bench.Run(FromCalibrationPress(press), &maps);
    SCOPED_TRACE(r.name);
    ASSERT_TRUE(r.truth_valid) << r.truth_press;
    EXPECT_TRUE(r.recon_ok);
    EXPECT_FALSE(r.recon_two_contacts);
    EXPECT_EQ(r.recon_object.shape, press.object.shape);
    EXPECT_EQ(r.recon_object.length_mm, 0.0);
    by_argmax += WithinTargets(r.recon_error);
    by_region += WithinTargets(r.recon_error, {}, true);
    char metrics[96];
    std::snprintf(metrics, sizeof metrics, "%.2f / %.2f / %.1f", r.recon_error.peak_ratio, r.recon_error.rel_l2,
                  r.recon_error.peak_offset_mm);
    RecordProperty(r.name, metrics);
  }
  EXPECT_GE(by_argmax, 5);
  EXPECT_EQ(by_region, 6);
}

// The synthetic set's 0.5 mm rod: its sensor presses it as it is, its truth presses it on the
// leader at contact::kLeaderMinRodRadius_mm, as the bridge and the rig presses' truths do (a thinner
// rod's ridge on model B can break into spots: docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s16).
// Rods the leader holds keep their radius.
TEST(FidelityCase, SyntheticTruthPressesAThinRodAtTheLeadersMinimum) {
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile("uskin_4x4");
  const std::vector<FidelityCase> cases = SyntheticFidelityCases(profile);
  auto find = [&](const std::string& name) {
    const auto it = std::find_if(cases.begin(), cases.end(), [&](const FidelityCase& c) { return c.name == name; });
    EXPECT_NE(it, cases.end()) << name;
    return it;
  };
  const auto thin = find("rod_r0.5_yaw0"), held = find("rod_r1_yaw30");
  ASSERT_NE(thin, cases.end());
  ASSERT_NE(held, cases.end());
  EXPECT_EQ(thin->primitive.radius_mm, 0.5);
  // Both rods start with their lowest line at the same lift above the pad; the axis is one
  // pressed radius above it.
  const double held_axis_mm = held->objects[0].trajectory.Pose(0).translation().z() * 1e3;
  const double thin_axis_mm = thin->objects[0].trajectory.Pose(0).translation().z() * 1e3;
  EXPECT_NEAR(thin_axis_mm - (held_axis_mm - 1.0), contact::kLeaderMinRodRadius_mm, 1e-9);
  const Eigen::Vector3d inside(0, 1e-3, (thin_axis_mm - 0.55) * 1e-3);  // 0.55 mm below the axis
  EXPECT_LT(thin->objects[0].Evaluate(inside, 0).distance_m, 0.0);      // inside 0.6 mm, not 0.5
}

// `fidelity --synthetic --random N`: rig-like presses the rig did not make, the same for the
// same seed, others for another, each a press that loads the pad to about the rig's forces.
TEST(FidelityCase, RandomSetIsSeededAndRigLike) {
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile("uskin_4x4");
  const auto a = SyntheticFidelityCases(profile, 5, sensors::PadMechanics::kLayer, 6);
  const auto b = SyntheticFidelityCases(profile, 5, sensors::PadMechanics::kLayer, 6);
  const auto c = SyntheticFidelityCases(profile, 6, sensors::PadMechanics::kLayer, 6);
  ASSERT_EQ(a.size(), 6u);
  int differ = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].label, b[i].label);
    ASSERT_EQ(a[i].scans.size(), b[i].scans.size());
    EXPECT_EQ(a[i].scans.back().raw_counts, b[i].scans.back().raw_counts);
    differ += a[i].label != c[i].label;
    EXPECT_TRUE(a[i].has_primitive) << a[i].name;
    double peak_N = 0;
    for (const Eigen::Vector3d& load : a[i].load_N) peak_N = std::max(peak_N, load.z());
    EXPECT_GT(peak_N, 0.05) << a[i].label;
    EXPECT_LT(peak_N, 3.0) << a[i].label;
  }
  EXPECT_GE(differ, 4);
  // Each drawn press has its own noise: the first scans (nothing touches yet) differ.
  int same_noise = 0;
  for (size_t i = 1; i < a.size(); ++i) same_noise += a[i].scans.front().raw_counts == a[0].scans.front().raw_counts;
  EXPECT_EQ(same_noise, 0);
}

// `--random-faces K`: K flat faces drawn after --random's presses (rectangular punches, round
// ones and bars in turn), from a stream of their own: the drawn presses before them are the
// same scans as without them; the faces are their punch primitives, pressed to the rig's
// forces. The fixed set ends with its three faces, after the presses it had.
TEST(FidelityCase, RandomFacesAreAddedAfterTheDrawnPressesWithoutChangingThem) {
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile("uskin_4x4");
  const auto plain = SyntheticFidelityCases(profile, 5, sensors::PadMechanics::kLayer, 4);
  const auto faces = SyntheticFidelityCases(profile, 5, sensors::PadMechanics::kLayer, 4, RandomRanges::kRig, 3);
  ASSERT_EQ(plain.size(), 4u);
  ASSERT_EQ(faces.size(), 7u);
  for (size_t i = 0; i < plain.size(); ++i) {
    EXPECT_EQ(plain[i].name, faces[i].name);
    ASSERT_EQ(plain[i].scans.size(), faces[i].scans.size());
    EXPECT_EQ(plain[i].scans.back().raw_counts, faces[i].scans.back().raw_counts) << plain[i].name;
  }
  const sensors::ContactShape kinds[3] = {sensors::ContactShape::kPunch, sensors::ContactShape::kRoundPunch,
                                          sensors::ContactShape::kPunch};
  const char* names[3] = {"random_04_punch", "random_05_round_punch", "random_06_bar"};
  for (int k = 0; k < 3; ++k) {
    const FidelityCase& c = faces[4 + size_t(k)];
    EXPECT_EQ(c.name, names[k]);
    ASSERT_TRUE(c.has_primitive);
    EXPECT_EQ(c.primitive.shape, kinds[k]) << c.name;
    double peak_N = 0;
    for (const Eigen::Vector3d& load : c.load_N) peak_N = std::max(peak_N, load.z());
    EXPECT_GT(peak_N, 0.3) << c.label;
    EXPECT_LT(peak_N, 3.0) << c.label;
  }
  const auto fixed = SyntheticFidelityCases(profile);
  ASSERT_GE(fixed.size(), 3u);
  EXPECT_EQ(fixed[fixed.size() - 3].name, "punch_4x2_yaw30");
  EXPECT_EQ(fixed[fixed.size() - 2].primitive.shape, sensors::ContactShape::kRoundPunch);
  EXPECT_EQ(fixed[fixed.size() - 2].primitive.radius_mm, 2.0);
  EXPECT_EQ(fixed.back().name, "bar_8x1.5_yaw-20");
}

// `--random-ranges wide` draws the same kinds in the same order as the rig ranges from a
// seed, at sizes and depths past the rig's: over 40 presses, spheres larger than 15 mm or
// smaller than 2 mm and rods thicker than 3 mm appear, and the pad carries both lighter and
// heavier presses than the rig ranges give it.
TEST(FidelityCase, WideRandomRangesGoPastTheRigs) {
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile("uskin_4x4");
  const auto rig = SyntheticFidelityCases(profile, 7, sensors::PadMechanics::kLayer, 40, RandomRanges::kRig);
  const auto wide = SyntheticFidelityCases(profile, 7, sensors::PadMechanics::kLayer, 40, RandomRanges::kWide);
  ASSERT_EQ(rig.size(), wide.size());
  auto peak_N = [](const FidelityCase& c) {
    double f = 0;
    for (const Eigen::Vector3d& load : c.load_N) f = std::max(f, load.z());
    return f;
  };
  int past_sphere = 0, past_rod = 0;
  double rig_min = 1e9, rig_max = 0, wide_min = 1e9, wide_max = 0;
  for (size_t i = 0; i < rig.size(); ++i) {
    EXPECT_EQ(rig[i].name, wide[i].name);  // the same kind at the same index
    rig_min = std::min(rig_min, peak_N(rig[i])), rig_max = std::max(rig_max, peak_N(rig[i]));
    wide_min = std::min(wide_min, peak_N(wide[i])), wide_max = std::max(wide_max, peak_N(wide[i]));
    if (!wide[i].has_primitive) continue;
    const sensors::ContactPrimitive& p = wide[i].primitive;
    if (p.shape == sensors::ContactShape::kSphere && (p.radius_mm > 15 || p.radius_mm < 2)) ++past_sphere;
    if (p.shape == sensors::ContactShape::kCylinder && p.radius_mm > 3) ++past_rod;
    if (p.shape == sensors::ContactShape::kSphere) {
      EXPECT_GE(p.radius_mm, 1.5) << wide[i].label;
      EXPECT_LE(p.radius_mm, 20.0) << wide[i].label;
    }
  }
  EXPECT_GE(past_sphere, 1);
  EXPECT_GE(past_rod, 1);
  EXPECT_LT(wide_min, rig_min);
  EXPECT_GT(wide_max, rig_max);
  EXPECT_EQ(config::EnumFromName<RandomRanges>("wide"), RandomRanges::kWide);
}

// Drawn strokes slide in any direction (the rig's go along +x and -y), and the load the
// simulated sensor carries at the peak scan drags along that direction.
TEST(FidelityCase, RandomStrokesSlideInAnyDirection) {
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile("uskin_4x4");
  const auto cases = SyntheticFidelityCases(profile, 3, sensors::PadMechanics::kLayer, 14);
  std::vector<double> directions_deg;
  for (const FidelityCase& c : cases) {
    if (c.name.find("stroke") == std::string::npos) continue;
    const size_t at = c.label.find(" at ");
    ASSERT_NE(at, std::string::npos) << c.label;
    const double yaw_deg = std::stod(c.label.substr(at + 4));
    directions_deg.push_back(yaw_deg);
    size_t peak = 0;
    for (size_t k = 0; k < c.load_N.size(); ++k)
      if (c.load_N[k].z() > c.load_N[peak].z()) peak = k;
    const Eigen::Vector2d shear = c.load_N[peak].head<2>();
    const Eigen::Vector2d slide(std::cos(yaw_deg * M_PI / 180), std::sin(yaw_deg * M_PI / 180));
    EXPECT_GT(shear.norm(), 0.2 * c.load_N[peak].z()) << c.label;  // sliding: mu 0.3
    EXPECT_GT(shear.normalized().dot(slide), std::cos(10 * M_PI / 180)) << c.label;
  }
  ASSERT_GE(directions_deg.size(), 3u);
  const auto [lo, hi] = std::minmax_element(directions_deg.begin(), directions_deg.end());
  EXPECT_GT(*hi - *lo, 90.0);
}

// The rig's presses 21-29 as the benchmark's truth presses them on the leader: a punch a box
// with its face on the pad, turned by its yaw; a pair both objects, the load the pair's; a
// rod ending on the pad a cylinder of its length.
TEST(FidelityCase, RigPunchPairAndFiniteRodAreTheirObjectsOnTheLeader) {
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile("uskin_4x4");
  const auto rig =
      sensors::LoadCalibrationPresses(config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), profile);
  ASSERT_EQ(rig.size(), 30u);
  auto distance_mm = [](const FidelityCase& c, size_t object, const Eigen::Vector3d& p_mm) {
    return 1e3 * c.objects[object].Evaluate(1e-3 * p_mm, 0.0).distance_m;
  };
  auto peak_N = [](const FidelityCase& c) {
    double f = 0;
    for (const Eigen::Vector3d& l : c.load_N) f = std::max(f, l.z());
    return f;
  };
  // press_22: a 6 x 6 mm punch turned 45 deg at (-1.5, 2), 1 N.
  const FidelityCase punch = FromCalibrationPress(rig[22]);
  EXPECT_EQ(punch.label, "punch 6x6 yaw 45 (-1.5, 2)");
  EXPECT_FALSE(punch.has_primitive);
  ASSERT_EQ(punch.objects.size(), 1u);
  const Eigen::Vector3d centre(-1.5, 2, 0), along(std::cos(M_PI / 4), std::sin(M_PI / 4), 0);
  EXPECT_NEAR(distance_mm(punch, 0, centre), 0.0, 1e-9);                  // its face on the pad
  EXPECT_LT(distance_mm(punch, 0, centre + 2.7 * along + Eigen::Vector3d(0, 0, 0.1)), 0.0);  // inside, near an edge
  EXPECT_GT(distance_mm(punch, 0, centre + 3.1 * along + Eigen::Vector3d(0, 0, 0.1)), 0.0);  // past the edge
  EXPECT_LT(distance_mm(punch, 0, centre + Eigen::Vector3d(3.5, 0, 0.1)), 0.0);  // its corner; unturned: outside
  EXPECT_DOUBLE_EQ(peak_N(punch), 1.0);
  // press_24: two 3 mm spheres, the pair's 0.8 N.
  const FidelityCase pair = FromCalibrationPress(rig[24]);
  EXPECT_EQ(pair.label, "pair: sphere R3 (-4, -2) 50%, sphere R3 (3, 3) 50%");
  ASSERT_EQ(pair.objects.size(), 2u);
  EXPECT_NEAR(distance_mm(pair, 0, Eigen::Vector3d(-4, -2, 0)), 0.0, 1e-9);
  EXPECT_NEAR(distance_mm(pair, 1, Eigen::Vector3d(3, 3, 0)), 0.0, 1e-9);
  EXPECT_NEAR(peak_N(pair), 0.8, 1e-12);
  // press_28: a 1.5 mm rod 6 mm long at yaw 120 through (-2, 0): its flat end 3 mm out.
  const FidelityCase rod = FromCalibrationPress(rig[28]);
  EXPECT_EQ(rod.label, "rod R1.5 L6 yaw 120 (-2, 0)");
  EXPECT_TRUE(rod.has_primitive);
  const Eigen::Vector3d axis(std::cos(2 * M_PI / 3), std::sin(2 * M_PI / 3), 0), on_axis(-2, 0, 1.5);
  EXPECT_LT(distance_mm(rod, 0, on_axis + 2.8 * axis), 0.0);
  EXPECT_GT(distance_mm(rod, 0, on_axis + 3.2 * axis), 0.0);
}

// `fidelity --rig-on-pad`: each rig press re-made on the simulated pad carries the press's
// force at its hold, at the rig's place, and a rig stroke's tangential load comes from a
// slide along it; a press the pad cannot carry is left out.
TEST(FidelityCase, RigPressesOnTheSimulatedPadCarryTheirForces) {
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile("uskin_4x4");
  const auto all =
      sensors::LoadCalibrationPresses(config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), profile);
  std::vector<sensors::CalibrationPress> presses;
  for (const auto& p : all)  // a sphere, a rod, a flat and a stroke (+x)
    if (p.name == "press_03.log" || p.name == "press_14.log" || p.name == "press_17.log" || p.name == "press_19.log")
      presses.push_back(p);
  ASSERT_EQ(presses.size(), 4u);
  sensors::CalibrationPress unreachable = presses[0];  // a 5 mm sphere cannot carry 50 N within its radius
  unreachable.name = "press_unreachable.log";
  unreachable.object.normal_force_N = 50;
  presses.push_back(unreachable);
  const auto cases = CalibrationPressesOnSimulatedPad(presses, profile, 1, sensors::PadMechanics::kLayer);
  ASSERT_EQ(cases.size(), 4u);
  for (size_t i = 0; i < cases.size(); ++i) {
    const sensors::ContactPrimitive& o = presses[i].object;
    const FidelityCase& c = cases[i];
    EXPECT_EQ(c.name + ".log", presses[i].name);
    ASSERT_TRUE(c.has_primitive);
    EXPECT_EQ(c.primitive.shape, o.shape) << c.name;
    EXPECT_EQ(c.primitive.radius_mm, o.radius_mm) << c.name;
    EXPECT_NEAR(c.primitive.x_mm, o.x_mm, 1e-9) << c.name;
    EXPECT_NEAR(c.primitive.y_mm, o.y_mm, 1e-9) << c.name;
    double peak_N = 0;
    size_t peak = 0;
    for (size_t k = 0; k < c.load_N.size(); ++k)
      if (c.load_N[k].z() > peak_N) peak_N = c.load_N[peak = k].z();
    EXPECT_NEAR(peak_N, o.normal_force_N, 0.03 * o.normal_force_N) << c.name;
    const double shear_ratio = c.load_N[peak].head<2>().norm() / peak_N;
    if (c.name == "press_19") {
      EXPECT_NEAR(shear_ratio, o.shear_x_N / o.normal_force_N, 0.03) << c.name;
      EXPECT_GT(c.load_N[peak].x(), 0.9 * c.load_N[peak].head<2>().norm()) << c.name;  // along +x, as the rig's
    } else {
      EXPECT_LT(shear_ratio, 0.01) << c.name;
    }
  }
}

// `fidelity --through-press`'s steadiness line: the step of the delivered / true peak ratio
// between neighbouring scored scans, none across a scan that is not scored.
TEST(FidelityBenchmark, PeakRatioStepsFollowTheTruthsOwnGrowth) {
  auto score = [](double truth_Pa, double recon_Pa, bool ok = true) {
    FidelityBenchmark::ScanScore s;
    s.truth_valid = true;
    s.recon_ok = ok;
    s.truth_max_sed_Pa = truth_Pa;
    s.recon_max_sed_Pa = recon_Pa;
    return s;
  };
  // A ramp the bridge follows at a steady 0.9 of the truth: no steps, however fast it grows.
  EXPECT_EQ(PeakRatioSteps({score(100, 90), score(400, 360), score(1600, 1440)}), std::vector<double>({0.0, 0.0}));
  // A radius that flickers: the ratio 1 -> 1.5 -> 1, steps log 1.5 each.
  const auto flicker = PeakRatioSteps({score(1000, 1000), score(1000, 1500), score(1000, 1000)});
  ASSERT_EQ(flicker.size(), 2u);
  EXPECT_NEAR(flicker[0], std::log(1.5), 1e-12);
  EXPECT_NEAR(flicker[1], std::log(1.5), 1e-12);
  // A fallback scan, a truth the leader could not carry and an empty peak break the chain.
  FidelityBenchmark::ScanScore no_truth = score(1000, 1000);
  no_truth.truth_valid = false;
  EXPECT_TRUE(PeakRatioSteps({score(1000, 1000), score(1000, 2000, false), score(1000, 1000)}).empty());
  EXPECT_TRUE(PeakRatioSteps({score(1000, 1000), no_truth, score(1000, 3000)}).empty());
  EXPECT_TRUE(PeakRatioSteps({score(0, 1000), score(1000, 1000)}).empty());
  EXPECT_TRUE(PeakRatioSteps({}).empty());
}

// `fidelity --through-press`: a press scored scan by scan through its ramp, hold and
// release, not only at its peak. Rig press_03 (a 5 mm sphere, 0.8 N): every 5th scan from a
// quarter of the peak force on, each with a truth and within the targets (measured 25 of 25).
TEST(FidelityBenchmark, ThroughThePressEveryScoredScanHasItsOwnTruth) {
  const RigBench rig;
  const FidelityCase press = FromCalibrationPress(rig.presses[3]);
  const auto scores = rig.bench->RunThroughPress(press, 5, 0.25);
  double peak_N = 0;
  for (const Eigen::Vector3d& load : press.load_N) peak_N = std::max(peak_N, load.z());
  size_t eligible = 0;  // scans from a quarter of the peak force: 5 of every 5 scored once
  for (const Eigen::Vector3d& load : press.load_N) eligible += load.z() >= 0.25 * peak_N;
  ASSERT_GE(scores.size(), eligible / 5);
  ASSERT_LE(scores.size(), eligible / 5 + 1);
  int within = 0;
  double lightest = peak_N, heaviest = 0, lightest_sed_Pa = 0, heaviest_sed_Pa = 0;
  for (size_t i = 0; i < scores.size(); ++i) {
    const auto& s = scores[i];
    SCOPED_TRACE(s.scan);
    EXPECT_GE(s.force_N, 0.25 * peak_N);
    if (i > 0) {
      EXPECT_GE(s.scan, scores[i - 1].scan + 5);
    }
    ASSERT_TRUE(s.truth_valid && s.recon_ok);
    // The truth is pressed at the scan's own force: its SED follows the ramp.
    if (s.force_N < lightest) lightest = s.force_N, lightest_sed_Pa = s.truth_max_sed_Pa;
    if (s.force_N > heaviest) heaviest = s.force_N, heaviest_sed_Pa = s.truth_max_sed_Pa;
    within += WithinTargets(s.recon_error);
  }
  EXPECT_LT(lightest, 0.4 * peak_N);  // the ramp and release are in, not only the hold
  EXPECT_GT(heaviest, 0.95 * peak_N);
  EXPECT_LT(lightest_sed_Pa, 0.8 * heaviest_sed_Pa);
  EXPECT_GE(within, int(scores.size()) - 1);
}

TEST(FidelityBenchmark, ObjectKindNamesStrokesByTheirTangentialLoad) {
  FidelityRow row;
  EXPECT_EQ(ObjectKind(row), "other");  // a box edge or corner, a pair
  row.truth_is_primitive = true;
  row.truth_object.shape = sensors::ContactShape::kSphere;
  row.truth_object.normal_force_N = 1.0;
  row.truth_object.shear_y_N = 0.04;
  EXPECT_EQ(ObjectKind(row), "sphere");
  row.truth_object.shear_x_N = -0.04;  // 0.057 N of 1 N: dragging
  EXPECT_EQ(ObjectKind(row), "stroke");
  row.truth_object.shape = sensors::ContactShape::kCylinder;
  EXPECT_EQ(ObjectKind(row), "rod");
  row.truth_object.shape = sensors::ContactShape::kFlat;
  EXPECT_EQ(ObjectKind(row), "flat");
}

TEST(FidelityBenchmark, WithinTargetsChecksAllThreeAtTheirBounds) {
  MethodError e;
  e.peak_ratio = 0.8;
  e.rel_l2 = 0.25;
  e.peak_offset_mm = 1.0;
  e.peak_region_offset_mm = 2.0;
  EXPECT_TRUE(WithinTargets(e));
  EXPECT_FALSE(WithinTargets(e, {}, true));  // by peak region: 2 mm
  MethodError high = e;
  high.peak_ratio = 1.26;
  EXPECT_FALSE(WithinTargets(high));
  MethodError l2 = e;
  l2.rel_l2 = 0.26;
  EXPECT_FALSE(WithinTargets(l2));
  MethodError far = e;
  far.peak_offset_mm = 1.01;
  EXPECT_FALSE(WithinTargets(far));
}

}  // namespace
}  // namespace sedbridge::fidelity
