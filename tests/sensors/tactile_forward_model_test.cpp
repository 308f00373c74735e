// The follower sensor's forward model: physics of the kernels, and the shipped calibration
// against the indentation-stage presses (config/sensors/rig_uskin_4x4/).
#include "sensors/tactile_forward_model.h"

#include <gtest/gtest.h>
#include "tests/common/scratch_dir.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/config_error.h"
#include "common/resource_path.h"
#include "sensors/calibration_press.h"
#include "sensors/tactile_model_fit.h"

namespace sedbridge::sensors {
namespace {

SensorProfile Uskin() { return LoadNamedSensorProfile("uskin_4x4"); }

// 1 / sigma of each reading of a 50-scan mean with 2-count single-scan noise [1/N]: the
// resolution at which a hold sees the readings.
Eigen::VectorXd InvSigmaOfAHoldMean(const SensorProfile& p) {
  Eigen::VectorXd inv_sigma(3 * p.taxel_count);
  for (int k = 0; k < p.taxel_count; ++k)
    for (int a = 0; a < 3; ++a) inv_sigma[3 * k + a] = std::sqrt(50.0) / (2.0 * NewtonsPerCount(p, k, a));
  return inv_sigma;
}

// Off-centre contacts with a tangential force, for the split-prediction checks.
ContactPrimitive DraggedSphere() {
  ContactPrimitive c;
  c.x_mm = 1.3, c.y_mm = -2.1, c.radius_mm = 6, c.normal_force_N = 0.9;
  c.shear_x_N = 0.1, c.shear_y_N = -0.05;
  return c;
}
ContactPrimitive DraggedRod(double radius_mm) {
  ContactPrimitive c = DraggedSphere();
  c.shape = ContactShape::kCylinder, c.radius_mm = radius_mm, c.yaw_deg = 20;
  return c;
}

TEST(TactileForwardModel, ShippedProfileHasACalibratedModel) {
  const SensorProfile p = Uskin();
  ASSERT_TRUE(p.has_forward_model);
  EXPECT_GT(p.forward_model.contact_modulus_kPa, 0);
}

TEST(TactileForwardModel, PatchCarriesTheForce) {
  const SensorProfile p = Uskin();
  TactileForwardModel m(p, p.forward_model);
  for (ContactShape s : {ContactShape::kSphere, ContactShape::kCylinder, ContactShape::kFlat}) {
    ContactPrimitive c;
    c.shape = s;
    c.radius_mm = 2;
    c.yaw_deg = 30;
    c.normal_force_N = 0.7;
    std::vector<SurfaceLoad> loads;
    m.Patch(c, &loads);
    double sum = 0;
    for (const auto& l : loads) sum += l.normal_N;
    EXPECT_NEAR(sum, 0.7, 1e-12) << ContactShapeName(s);
  }
}

// The reconstruction's budgets estimate an evaluation's cost before computing it: the
// estimate follows the patch Patch() loads, from a thin rod to a sphere over the pad, and
// for finite rods.
TEST(TactileForwardModel, PatchCellsEstimateFollowsThePatch) {
  const SensorProfile p = Uskin();
  TactileForwardModel m(p, p.forward_model);
  int checked = 0;
  for (ContactShape s : {ContactShape::kSphere, ContactShape::kCylinder})
    for (double radius_mm : {0.6, 2.5, 8.0, 40.0})
      for (double force_N : {0.05, 0.5, 2.0})
        for (double length_mm : {0.0, 6.0}) {
          if (s == ContactShape::kSphere && length_mm > 0) continue;
          ContactPrimitive c;
          c.shape = s;
          c.radius_mm = radius_mm;
          c.normal_force_N = force_N;
          c.length_mm = length_mm;
          c.x_mm = 1.5, c.y_mm = -2, c.yaw_deg = 35;
          std::vector<SurfaceLoad> loads;
          m.Patch(c, &loads);
          const double estimate = m.PatchCellsEstimate(c);
          EXPECT_GT(estimate, 0.6 * double(loads.size())) << ContactShapeName(s) << " R " << radius_mm << " F " << force_N;
          EXPECT_LT(estimate, 1.4 * double(loads.size()) + 4) << ContactShapeName(s) << " R " << radius_mm << " F " << force_N;
          ++checked;
        }
  EXPECT_EQ(checked, 36);
  ContactPrimitive flat;
  flat.shape = ContactShape::kFlat;
  flat.normal_force_N = 1;
  EXPECT_EQ(m.PatchCellsEstimate(flat), 0.0);
  ContactPrimitive none;
  none.normal_force_N = 0;
  EXPECT_EQ(m.PatchCellsEstimate(none), 0.0);
}

TEST(TactileForwardModel, CentredSphereIsSymmetricAndShearPointsOutward) {
  const SensorProfile p = Uskin();
  TactileForwardModel m(p, p.forward_model);
  ContactPrimitive c;
  c.radius_mm = 5;
  c.normal_force_N = 0.8;
  Eigen::VectorXd r;
  m.Predict(c, &r);
  // Taxels 5, 6, 9, 10 are the inner four: same normal reading, shear away from the load.
  for (int k : {6, 9, 10}) EXPECT_NEAR(r[3 * k + 2], r[3 * 5 + 2], 1e-9);
  EXPECT_LT(r[3 * 5], 0);  // taxel 5 at (-2.35, -2.35): outward is -x
  EXPECT_GT(r[3 * 6], 0);
  double sum_z = 0;
  for (int k = 0; k < 16; ++k) sum_z += r[3 * k + 2];
  EXPECT_LT(sum_z, 0.8);  // part of the load never reaches the taxels
  EXPECT_GT(sum_z, 0.3);
}

TEST(TactileForwardModel, SphereRadiusChangesThePattern) {
  // The information the old Winkler sensor lacked: at equal force, a sharper sphere has a
  // larger shear-to-normal ratio on the inner taxels.
  const SensorProfile p = Uskin();
  TactileForwardModel m(p, p.forward_model);
  ContactPrimitive a, b;
  a.radius_mm = 2;
  b.radius_mm = 10;
  a.normal_force_N = b.normal_force_N = 0.8;
  Eigen::VectorXd ra, rb;
  m.Predict(a, &ra);
  m.Predict(b, &rb);
  EXPECT_GT(std::abs(ra[3 * 5]) / ra[3 * 5 + 2], 1.2 * std::abs(rb[3 * 5]) / rb[3 * 5 + 2]);
}

TEST(TactileForwardModel, ZeroForceGivesZero) {
  const SensorProfile p = Uskin();
  TactileForwardModel m(p, p.forward_model);
  ContactPrimitive c;
  Eigen::VectorXd r;
  m.Predict(c, &r);
  EXPECT_EQ(r.size(), 48);
  EXPECT_EQ(r.norm(), 0.0);
  c.normal_force_N = std::nan("");
  m.Predict(c, &r);
  EXPECT_EQ(r.norm(), 0.0);
}

TEST(TactileForwardModel, RejectsBadKernels) {
  const SensorProfile p = Uskin();
  TactileModelParams bad = p.forward_model;
  bad.normal.width_mm = 0;
  EXPECT_THROW(TactileForwardModel(p, bad), std::invalid_argument);
}

TEST(TactileForwardModel, ReproducesEveryRigPressWithinNoise) {
  const SensorProfile p = Uskin();
  auto presses = LoadCalibrationPresses(config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), p);
  ASSERT_EQ(presses.size(), 30u);
  presses.resize(21);  // 00-20: what the shipped forward_model was fitted to
  for (const auto& r : EvaluateTactileModel(presses, p, p.forward_model)) {
    // RMS of the hold-window error in units of the single-scan noise.
    for (int a = 0; a < 3; ++a) EXPECT_LT(r.rms_sigma[a], 1.0) << r.name << " axis " << a;
    EXPECT_NEAR(r.predicted_sum_z_N, r.measured_sum_z_N, 0.03 * r.measured_sum_z_N + 0.005) << r.name;
  }
}

TEST(CalibrationPress, BadCasesFileNamesTheLocation) {
  const std::string path = sedbridge::testing::ScratchDir() + "/cases_bad.json";
  {
    std::ofstream f(path);
    f << "{\"cases\": [{\"object\": {\"shape\": \"cone\", \"position_mm\": [0, 0]}, \"force_N\": 1, \"log\": \"x.log\"}]}";
  }
  try {
    LoadCalibrationPresses(path, Uskin());
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(":1:"), std::string::npos) << e.what();
  }
}

// The rig's press_03 (a 5 mm sphere at the centre, 0.8 N) as a one-press cases file `name`
// in the scratch folder, its log at `log`, with `top_level` keys before `cases` (e.g.
// "\"protocol\": {...}, "), loaded.
std::vector<CalibrationPress> LoadOneSpherePress(const std::string& name, const std::string& log,
                                                 const std::string& top_level = "") {
  const std::string path = sedbridge::testing::ScratchDir() + "/" + name;
  {
    std::ofstream f(path);
    f << "{" << top_level << "\"cases\": [{\"object\": {\"shape\": \"sphere\", \"position_mm\": [0, 0], "
         "\"radius_mm\": 5}, \"force_N\": 0.8, \"log\": \"" << log << "\"}]}";
  }
  return LoadCalibrationPresses(path, Uskin());
}

std::string RigPress03Path() {
  return std::filesystem::absolute(config::ResolveResource("config/sensors/rig_uskin_4x4/press_03.log"))
      .lexically_normal()
      .string();
}

// A cases file may name logs kept elsewhere by absolute path (a held-out selection of the
// rig's presses in a scratch folder): used as given, named by the file's own name.
TEST(CalibrationPress, AbsoluteLogPathsAreUsedAsGiven) {
  const std::string log = RigPress03Path();
  const auto presses = LoadOneSpherePress("cases_abs.json", log);
  ASSERT_EQ(presses.size(), 1u);
  EXPECT_EQ(presses[0].name, "press_03.log");
  EXPECT_EQ(presses[0].log_path, log);
  EXPECT_GT(presses[0].scans.size(), 100u);
}

// The error a cases file with `cases_json` gives ("" = none).
std::string CasesError(const std::string& cases_json) {
  const std::string path = sedbridge::testing::ScratchDir() + "/cases_err.json";
  {
    std::ofstream f(path);
    f << cases_json;
  }
  try {
    LoadCalibrationPresses(path, Uskin());
  } catch (const config::ConfigError& e) {
    return std::string(e.what()).substr(path.size());
  }
  return "";
}

// A cases file whose stage ran another protocol says so (`protocol:`, keys left out keep
// the rig's): every press's load over time follows it, and a ramp window placed on the rig's
// ramp lands at the same load fraction.
TEST(CalibrationPress, ProtocolKeySetsEveryPressesLoadOverTime) {
  const auto presses =
      LoadOneSpherePress("cases_protocol.json", RigPress03Path(), "\"protocol\": {\"unloaded_s\": 0.5, \"hold_s\": 0.6}, ");
  ASSERT_EQ(presses.size(), 1u);
  const PressProtocol& p = presses[0].protocol;
  EXPECT_EQ(p.unloaded_s, 0.5);
  EXPECT_EQ(p.ramp_s, PressProtocol{}.ramp_s);
  EXPECT_EQ(p.hold_s, 0.6);
  EXPECT_EQ(presses[0].ObjectAt(0.45).normal_force_N, 0.0);
  EXPECT_NEAR(presses[0].ObjectAt(0.85).normal_force_N, 0.4, 1e-12);   // half way up the ramp
  EXPECT_NEAR(presses[0].ObjectAt(1.7).normal_force_N, 0.8, 1e-12);    // in the 0.6 s hold
  EXPECT_NEAR(p.FromRigTime_s(0.5), 0.7, 1e-12);  // 2/7 of the ramp in both
  EXPECT_EQ(PressProtocol{}.FromRigTime_s(0.5), 0.5);
  // The rig's own cases file has none: the rig's protocol.
  const auto rig = LoadCalibrationPresses(config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), Uskin());
  EXPECT_EQ(rig[0].protocol.unloaded_s, PressProtocol{}.unloaded_s);
}

// The same press recorded 0.2 s later (20 more unloaded scans first) reads the same once its
// cases file says so: the fit's hold window then holds the same scans; without the key the
// window starts on the ramp.
TEST(CalibrationPress, ALaterStartReadsTheSameWithItsProtocol) {
  const std::string orig = RigPress03Path();
  const std::string dir = sedbridge::testing::ScratchDir();
  const std::string late = dir + "/press_03_late.log";
  {
    std::ifstream in(orig);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    ASSERT_GT(lines.size(), 320u);
    std::ofstream out(late);
    for (size_t i = 0; i < 320; ++i) out << lines[i] << "\n";  // 20 scans of 16 frames, unloaded
    for (const std::string& line : lines) {  // "(SSSSSSSSSS.UUUUUU) can0 ID#DATA", 0.2 s later
      const size_t dot = line.find('.'), close = line.find(')');
      long long sec = std::stoll(line.substr(1, dot - 1)), us = std::stoll(line.substr(dot + 1, close - dot - 1)) + 200000;
      sec += us / 1000000, us %= 1000000;
      char stamp[32];
      std::snprintf(stamp, sizeof stamp, "(%lld.%06lld)", sec, us);
      out << stamp << line.substr(close + 1) << "\n";
    }
  }
  const SensorProfile profile = Uskin();
  const auto original = LoadOneSpherePress("cases_orig.json", orig);
  const auto told = LoadOneSpherePress("cases_late.json", late, "\"protocol\": {\"unloaded_s\": 0.5}, ");
  const auto untold = LoadOneSpherePress("cases_late_untold.json", late);
  ASSERT_EQ(told[0].scans.size(), original[0].scans.size() + 20);
  for (double t : {0.2, 0.6, 1.25, 1.65, 1.9})
    EXPECT_NEAR(told[0].ObjectAt(t + 0.2).normal_force_N, original[0].ObjectAt(t).normal_force_N, 1e-12) << t;
  const PressFitReport a = EvaluateTactileModel(original, profile, profile.forward_model)[0];
  const PressFitReport b = EvaluateTactileModel(told, profile, profile.forward_model)[0];
  const PressFitReport c = EvaluateTactileModel(untold, profile, profile.forward_model)[0];
  for (int axis = 0; axis < 3; ++axis) EXPECT_NEAR(b.rms_sigma[axis], a.rms_sigma[axis], 0.05) << axis;
  EXPECT_NEAR(b.measured_sum_z_N, a.measured_sum_z_N, 1e-3 * a.measured_sum_z_N);
  EXPECT_LT(c.measured_sum_z_N, 0.99 * a.measured_sum_z_N);  // the ramp's lighter scans in the window
  EXPECT_GT(c.rms_sigma[2], 2 * a.rms_sigma[2]);
}

TEST(CalibrationPress, ProtocolKeysAreCheckedWhereTheyStand) {
  EXPECT_NE(CasesError("{\"protocol\": {\"ramp_s\": 0}, \"cases\": []}").find(":1:25: 'ramp_s' must be > 0 (got 0)"),
            std::string::npos)
      << CasesError("{\"protocol\": {\"ramp_s\": 0}, \"cases\": []}");
  EXPECT_NE(CasesError("{\"protocol\": {\"ramp\": 1}, \"cases\": []}").find("unknown key 'ramp'"), std::string::npos)
      << CasesError("{\"protocol\": {\"ramp\": 1}, \"cases\": []}");
}

TEST(CalibrationPress, CaseKeysAreCheckedWhereTheyStand) {
  EXPECT_EQ(CasesError("{\"cases\": [{\"object\": {\"shape\": \"cone\", \"position_mm\": [0, 0]}, \"force_N\": 1, \"log\": \"x.log\"}]}"),
            ":1:33: 'shape' must be one of: sphere, cylinder, flat, punch, pair (got 'cone')");
  EXPECT_EQ(CasesError("{\"cases\": [{\"object\": {\"shape\": \"sphere\", \"position_mm\": [0, 0]}, \"force_N\": 1, \"log\": \"x.log\"}]}"),
            ":1:23: 'radius_mm' (> 0) is required for a sphere");
  EXPECT_EQ(CasesError("{\"cases\": [{\"object\": {\"shape\": \"flat\", \"position_mm\": [0, 0]}, \"force_N\": 2000, \"log\": \"x.log\"}]}"),
            ":1:76: 'force_N' must be in (0, 1000] N (got 2000)");
  EXPECT_EQ(CasesError("{\"cases\": 3}"), ":1:11: 'cases' must be a list");
  EXPECT_EQ(ContactShapeFromName(ContactShapeName(ContactShape::kCylinder)), ContactShape::kCylinder);
}

}  // namespace
}  // namespace sedbridge::sensors

namespace sedbridge::sensors {
namespace {

TEST(TactileForwardModel, FlatShortcutEqualsThePatch) {
  const SensorProfile p = Uskin();
  TactileForwardModel m(p, p.forward_model);
  ContactPrimitive c;
  c.shape = ContactShape::kFlat;
  c.normal_force_N = 1.3;
  c.shear_x_N = 0.2;
  c.shear_y_N = -0.1;
  Eigen::VectorXd fast, slow;
  m.Predict(c, &fast);
  std::vector<SurfaceLoad> loads;
  m.Patch(c, &loads);
  m.Respond(loads, &slow);
  EXPECT_LT((fast - slow).norm(), 1e-12 * slow.norm());
}

}  // namespace
}  // namespace sedbridge::sensors

namespace sedbridge::sensors {
namespace {

// The reconstruction's Jacobian takes the tangential columns from the split prediction:
// recombined it must be Predict, for every shape.
TEST(TactileForwardModel, PredictLinearInShearRecombinesToPredict) {
  const SensorProfile p = Uskin();
  TactileForwardModel m(p, p.forward_model);
  const ContactPrimitive sphere = DraggedSphere(), rod = DraggedRod(1.0);
  ContactPrimitive flat = sphere;
  flat.shape = ContactShape::kFlat;
  for (const ContactPrimitive& c : {sphere, rod, flat}) {
    Eigen::VectorXd expected, normal, per_x, per_y;
    m.Predict(c, &expected);
    m.PredictLinearInShear(c, &normal, &per_x, &per_y);
    const Eigen::VectorXd recombined = normal + c.shear_x_N * per_x + c.shear_y_N * per_y;
    EXPECT_GT(per_x.norm(), 0) << ContactShapeName(c.shape);
    EXPECT_LT((recombined - expected).norm(), 1e-12 * expected.norm()) << ContactShapeName(c.shape);
  }
}

}  // namespace
}  // namespace sedbridge::sensors

namespace sedbridge::sensors {
namespace {

// A rod's patch is only a few load-grid cells wide. Sampled at cell centres, the Hertz strip
// gains or loses a cell with a square-root kink as its half-width grows, and the readings
// jumped with the radius by more than the noise of a hold's mean (chi^2 of the rig's 1 mm rod
// hold moved by tens between R and 1.05 R): the reconstruction could not settle a rod's
// radius. Averaged over each cell, the readings are smooth: their second difference over a
// 2 % radius step stays below 0.2 noise units of a 50-scan mean (cell-centre sampling gave
// 1.7-10.8 at these poses).
TEST(TactileForwardModel, RodReadingsAreSmoothInItsRadius) {
  const SensorProfile p = Uskin();
  TactileForwardModel m(p, p.forward_model);
  const Eigen::VectorXd inv_sigma_mean = InvSigmaOfAHoldMean(p);
  for (double yaw_deg : {0.0, 45.0, 80.0}) {
    ContactPrimitive c;
    c.shape = ContactShape::kCylinder;
    c.yaw_deg = yaw_deg;
    c.x_mm = 0.3;
    c.y_mm = -0.4;
    c.normal_force_N = 0.5;
    std::vector<Eigen::VectorXd> r;
    for (double R = 0.8; R < 3.2; R *= 1.02) {
      c.radius_mm = R;
      Eigen::VectorXd out;
      m.Predict(c, &out);
      r.push_back(out.cwiseProduct(inv_sigma_mean));
    }
    double worst_second = 0;
    for (size_t i = 1; i + 1 < r.size(); ++i)
      worst_second = std::max(worst_second, (r[i + 1] - 2 * r[i] + r[i - 1]).norm());
    EXPECT_LT(worst_second, 0.2) << "yaw " << yaw_deg;
  }
}

}  // namespace
}  // namespace sedbridge::sensors

namespace sedbridge::sensors {
namespace {

// The reconstruction's force column is d pred / d log F = normal part + d pred / d log R:
// the patch depends on F and R only through its Hertz half-width (a^3 ~ F R, b^2 ~ F R / L)
// and the normal part is F times a function of it. Checked by central differences on both
// sides, tangential force included (it spreads over the same patch).
// Each cell of a rod's patch carries the Hertz line-contact profile sqrt(1 - t^2) averaged
// over the cell's width across the axis (t in units of the half-width b): checked against
// the profile's antiderivative, (t sqrt(1 - t^2) + asin t) / 2, on every cell inside the pad,
// whatever route (scalar or vector arcsine) the model takes to it.
TEST(TactileForwardModel, RodPatchIsTheHertzProfileAveragedOverEachCell) {
  SensorProfile p = Uskin();
  // As shipped, and with a rod band floor above the grid (rod_min_halfwidth_mm).
  for (double floor_mm : {p.forward_model.rod_min_halfwidth_mm, 0.3}) {
  p.forward_model.rod_min_halfwidth_mm = floor_mm;
  TactileForwardModel m(p, p.forward_model);
  const double kPi = 3.14159265358979323846;
  const double h = m.cell_size_mm(), half = 0.5 * m.params().pad_size_mm;
  const double E_N_mm2 = m.params().contact_modulus_kPa * 1e-3;
  auto antiderivative = [](double u) { return 0.5 * (u * std::sqrt(1 - u * u) + std::asin(u)); };
  for (double yaw_deg : {0.0, 30.0, 70.0}) {
    for (double radius_mm : {0.5, 1.5, 4.0}) {
      ContactPrimitive c;
      c.shape = ContactShape::kCylinder, c.radius_mm = radius_mm, c.yaw_deg = yaw_deg, c.normal_force_N = 0.8;
      const double yaw = yaw_deg * kPi / 180, dx = std::cos(yaw), dy = std::sin(yaw);
      const double L = 2 * half / std::max(std::abs(dx), std::abs(dy));  // through the centre
      // Widened by the cover's spread (rod_min_halfwidth_mm), at least one cell.
      const double w = std::max(h, m.params().rod_min_halfwidth_mm);
      const double b = std::hypot(std::sqrt(4 * (c.normal_force_N / L) * radius_mm / (kPi * E_N_mm2)), w);
      std::vector<SurfaceLoad> loads;
      m.Patch(c, &loads);
      ASSERT_GT(loads.size(), 20u);
      std::vector<std::pair<double, double>> load_and_strip;  // cells inside the pad
      for (const SurfaceLoad& l : loads) {
        const Eigen::Vector2d x = m.CellCentre_mm(l.cell);
        if (std::abs(x.x()) + 0.5 * h > half || std::abs(x.y()) + 0.5 * h > half) continue;  // the pad's edge
        const double t = (-x.x() * dy + x.y() * dx) / b, t_half = 0.5 * h / b;
        const double strip = antiderivative(std::min(1.0, t + t_half)) - antiderivative(std::max(-1.0, t - t_half));
        ASSERT_GT(strip, 0) << "a loaded cell outside the contact strip";
        load_and_strip.emplace_back(l.normal_N, strip);
      }
      const int inside = static_cast<int>(load_and_strip.size());
      // Load per unit of the profile's integral, from the cell that carries the most (the
      // antiderivative's difference loses digits on a sliver at the strip's edge).
      const auto fullest = *std::max_element(load_and_strip.begin(), load_and_strip.end(),
                                             [](const auto& a, const auto& z) { return a.second < z.second; });
      const double scale = fullest.first / fullest.second;
      for (const auto& [load, strip] : load_and_strip)
        EXPECT_NEAR(load, scale * strip, 1e-13 * scale)
            << "floor " << floor_mm << ", yaw " << yaw_deg << ", R " << radius_mm << ", strip " << strip;
      EXPECT_GT(inside, 20);
    }
  }
  }
}

// fit-sensor --rod-radii: a rod's hold that the model itself rendered is read back at its
// radius (pose, force, shear free), whatever the band floor; a rod much thinner than the
// floor's band reads thinner than its radius, towards 0 (the band no longer tells it).
TEST(TactileModelFit, RodRadiiReadTheModelsOwnRodsBack) {
  SensorProfile p = Uskin();
  for (double floor_mm : {0.0, 0.3}) {
    p.forward_model.rod_min_halfwidth_mm = floor_mm;
    const TactileForwardModel model(p, p.forward_model);
    std::vector<CalibrationPress> presses;
    const double radii[] = {1.0, 2.5, 0.2};
    for (double radius_mm : radii) {
      CalibrationPress press;
      press.name = "rod_" + std::to_string(radius_mm);
      press.object.shape = ContactShape::kCylinder;
      press.object.radius_mm = radius_mm;
      press.object.x_mm = 0.4, press.object.y_mm = -0.7, press.object.yaw_deg = 25, press.object.normal_force_N = 0.5;
      Eigen::VectorXd hold;
      model.Predict(press.object, &hold);
      for (double t = 1.0; t <= 1.5; t += 0.01) press.t_s.push_back(t), press.readings_N.push_back(hold);
      presses.push_back(press);
    }
    presses.push_back(presses[0]);
    presses.back().object.shape = ContactShape::kSphere;  // not a rod: not reported
    const std::vector<RodRadiusReport> rods = FitRodRadii(presses, p, p.forward_model);
    ASSERT_EQ(rods.size(), 3u);
    EXPECT_NEAR(rods[0].fitted_radius_mm, 1.0, 0.01) << floor_mm;
    EXPECT_NEAR(rods[1].fitted_radius_mm, 2.5, 0.025) << floor_mm;
    EXPECT_LT(rods[0].chi2, 1e-6) << floor_mm;
    EXPECT_LT(rods[2].fitted_radius_mm, 0.2 * 1.05) << floor_mm;  // at or below the truth, never above
    EXPECT_EQ(rods[0].true_radius_mm, 1.0);
  }
}

TEST(TactileForwardModel, ForceAndRadiusEnterThroughTheHertzWidthOnly) {
  const SensorProfile p = Uskin();
  TactileForwardModel m(p, p.forward_model);
  const double h = 1e-4;
  ContactPrimitive edge = DraggedRod(1.5);
  edge.length_mm = 8;  // a finite rod: b^2 ~ F R / L with L its own length
  for (const ContactPrimitive& c : {DraggedSphere(), DraggedRod(1.5), edge}) {
    auto at = [&](double log_f, double log_r) {
      ContactPrimitive q = c;
      q.normal_force_N = c.normal_force_N * std::exp(log_f);
      q.radius_mm = c.radius_mm * std::exp(log_r);
      q.shear_x_N = c.shear_x_N, q.shear_y_N = c.shear_y_N;  // T is its own unknown
      Eigen::VectorXd out;
      m.Predict(q, &out);
      return out;
    };
    const Eigen::VectorXd d_log_f = (at(h, 0) - at(-h, 0)) / (2 * h);
    const Eigen::VectorXd d_log_r = (at(0, h) - at(0, -h)) / (2 * h);
    Eigen::VectorXd normal, per_x, per_y;
    m.PredictLinearInShear(c, &normal, &per_x, &per_y);
    // R matters (a rod's reading hardly, but 100x above the tolerance below).
    EXPECT_GT(d_log_r.norm(), 1e-3 * normal.norm()) << ContactShapeName(c.shape);
    EXPECT_LT((d_log_f - (normal + d_log_r)).norm(), 1e-5 * normal.norm()) << ContactShapeName(c.shape);
  }
}

}  // namespace
}  // namespace sedbridge::sensors

namespace sedbridge::sensors {
namespace {

// A finite rod (an edge) loads only its own length: one whose length exceeds the axis's
// chord across the pad reads exactly as the rod that crosses it; a 6 mm one loads a
// quarter to a third of the taxels a crossing one does and is centred where it lies.
TEST(TactileForwardModel, FiniteRodLoadsOnlyItsLength) {
  const SensorProfile p = Uskin();
  TactileForwardModel m(p, p.forward_model);
  ContactPrimitive rod = DraggedRod(1.0);
  rod.x_mm = 0.5, rod.y_mm = -1.0, rod.yaw_deg = 0;
  const double chord = m.RodLengthOnPad_mm(rod);
  EXPECT_NEAR(chord, p.forward_model.pad_size_mm, 1e-9);  // along x through the pad
  ContactPrimitive long_edge = rod;
  long_edge.length_mm = 2 * (chord + 5);
  Eigen::VectorXd a, b;
  m.Predict(rod, &a);
  m.Predict(long_edge, &b);
  EXPECT_LT((a - b).norm(), 1e-12 * a.norm());
  ContactPrimitive edge = rod;
  edge.length_mm = 6;
  EXPECT_NEAR(m.RodLengthOnPad_mm(edge), 6.0, 1e-9);
  EXPECT_EQ(m.RodLengthOnPad_mm(DraggedSphere()), 0.0);
  Eigen::VectorXd e;
  m.Predict(edge, &e);
  // The same force on a shorter line: the taxels over it read more, the outer columns
  // (x = +-7.05 mm, more than 3 mm beyond its ends) far less.
  double inner_a = 0, inner_e = 0, outer_a = 0, outer_e = 0;
  for (int k = 0; k < p.taxel_count; ++k) {
    const bool inner = std::abs(p.taxels[size_t(k)].x_mm - edge.x_mm) < 4;
    (inner ? inner_a : outer_a) += a[3 * k + 2];
    (inner ? inner_e : outer_e) += e[3 * k + 2];
  }
  EXPECT_GT(inner_e, 1.3 * inner_a);
  EXPECT_LT(outer_e, 0.5 * outer_a);
}

// The readings are smooth (C1) in a finite rod's length, so the reconstruction's finite
// differences in its length and centre are meaningful: halving the step quarters the worst
// second difference (a curve); with a kink at every cell boundary (a box-shaped cell's share
// of the rod, tried first) it did not shrink (0.4-2.4 times the coarse one). Measured 0.26-0.31.
TEST(TactileForwardModel, FiniteRodReadingsAreSmoothInItsLength) {
  const SensorProfile p = Uskin();
  TactileForwardModel m(p, p.forward_model);
  const Eigen::VectorXd inv_sigma_mean = InvSigmaOfAHoldMean(p);
  for (double yaw_deg : {0.0, 30.0, 80.0}) {
    ContactPrimitive c = DraggedRod(1.0);
    c.yaw_deg = yaw_deg;
    c.shear_x_N = c.shear_y_N = 0;
    auto worst_second = [&](double step) {
      std::vector<Eigen::VectorXd> r;
      for (double length = 4; length < 12; length *= step) {
        c.length_mm = length;
        Eigen::VectorXd out;
        m.Predict(c, &out);
        r.push_back(out.cwiseProduct(inv_sigma_mean));
      }
      double worst = 0;
      for (size_t i = 1; i + 1 < r.size(); ++i) worst = std::max(worst, (r[i + 1] - 2 * r[i] + r[i - 1]).norm());
      return worst;
    };
    const double coarse = worst_second(1.02), fine = worst_second(1.01);
    EXPECT_GT(coarse, 0);
    EXPECT_LT(fine, 0.4 * coarse) << "yaw " << yaw_deg << ": " << fine << " vs " << coarse;
  }
}

}  // namespace
}  // namespace sedbridge::sensors

namespace sedbridge::sensors {
namespace {

// The tangential kernels are seen only by the presses with a traction (the rig's press_19
// along x, press_20 along y). Fitted from the generic start on a few presses with press_20
// the only traction, the model must still explain press_19 (the same isotropic kernels, the
// other direction) and press_20 itself: a one-start joint fit stalled at 6-10 sigma on both
// (docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s15).
TEST(TactileModelFit, OneTractionPressCalibratesTheOtherDirection) {
  const SensorProfile p = Uskin();
  const auto rig = LoadCalibrationPresses(config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), p);
  std::vector<CalibrationPress> fit_set, held_out;
  for (const auto& press : rig) {
    for (const char* name : {"press_00.log", "press_03.log", "press_06.log", "press_09.log", "press_12.log",
                             "press_17.log", "press_20.log"})
      if (press.name == name) fit_set.push_back(press);
    if (press.name == "press_19.log") held_out.push_back(press);
  }
  ASSERT_EQ(fit_set.size(), 7u);
  ASSERT_EQ(held_out.size(), 1u);
  TactileModelParams initial = InitialTactileModelParams();
  initial.rod_min_halfwidth_mm = p.forward_model.rod_min_halfwidth_mm;
  const FitReport fit = FitTactileModel(fit_set, p, initial);
  for (const auto& r : fit.presses)
    for (int a = 0; a < 3; ++a) EXPECT_LT(r.rms_sigma[a], 1.0) << r.name << " axis " << a << ", " << fit.status;
  const auto held = EvaluateTactileModel(held_out, p, fit.params);
  for (int a = 0; a < 3; ++a) EXPECT_LT(held[0].rms_sigma[a], 1.0) << "press_19 axis " << a << ", " << fit.status;
}

}  // namespace
}  // namespace sedbridge::sensors
