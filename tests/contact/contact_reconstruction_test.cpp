// Contact reconstruction on the calibration rig's presses and on the hard cases
// (contact appearing/vanishing, sliding across taxels, two contacts, saturation, NaN, a fit
// that diverges).
#include "contact/contact_reconstruction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/resource_path.h"
#include "sensors/calibration_press.h"
#include "tests/contact/reconstruction_test_support.h"

namespace sedbridge::contact {
namespace {

using sensors::ContactPrimitive;
using sensors::ContactShape;

using test_support::HeldFor;
using test_support::Noisy;
using test_support::ReadingsOf;
using test_support::SphereAt;
using test_support::Uskin;

const std::vector<sensors::CalibrationPress>& Rig() {
  static const auto presses = sensors::LoadCalibrationPresses(
      config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), Uskin());
  return presses;
}

// Runs the reconstructor through a press up to the middle of the hold; returns that estimate.
ContactEstimate AtHold(const sensors::CalibrationPress& press, ContactReconstructor* r) {
  const double t_hold = sensors::PressProtocol().HoldMid_s();
  ContactEstimate e;
  for (size_t i = 0; i < press.scans.size() && press.t_s[i] <= t_hold; ++i) e = r->Reconstruct(press.scans[i]);
  return e;
}

TEST(ContactReconstruction, RigSpheresFromOneNoisyScan) {
  for (int i : {0, 1, 3, 5, 6, 9, 10, 11}) {
    const auto& press = Rig()[size_t(i)];
    ContactReconstructor r(Uskin());
    const ContactEstimate e = AtHold(press, &r);
    ASSERT_TRUE(e.ok) << press.name << ": " << e.problem;
    EXPECT_EQ(e.primitive.shape, ContactShape::kSphere) << press.name;
    EXPECT_LT(std::hypot(e.primitive.x_mm - press.object.x_mm, e.primitive.y_mm - press.object.y_mm), 0.3) << press.name;
    // press_11 sits on the pad's corner: only a quarter of its pattern falls on taxels and
    // its radius is not determined there (docs/bridge-fidelity.md); position and force are.
    if (press.name != "press_11.log") {
      EXPECT_NEAR(e.primitive.radius_mm, press.object.radius_mm, 0.3 * press.object.radius_mm) << press.name;
    }
    EXPECT_NEAR(e.primitive.normal_force_N, press.object.normal_force_N, 0.05 * press.object.normal_force_N)
        << press.name;
    EXPECT_LT(e.rms_sigma, 1.5) << press.name;
  }
}

TEST(ContactReconstruction, RigRodsAndFlats) {
  for (int i : {12, 13, 14, 15, 16}) {
    const auto& press = Rig()[size_t(i)];
    ContactReconstructor r(Uskin());
    const ContactEstimate e = AtHold(press, &r);
    ASSERT_TRUE(e.ok) << press.name << ": " << e.problem;
    EXPECT_EQ(e.primitive.shape, ContactShape::kCylinder) << press.name;
    const double yaw_error = std::remainder(e.primitive.yaw_deg - press.object.yaw_deg, 180.0);
    EXPECT_LT(std::abs(yaw_error), 3.0) << press.name;
    // Distance of the true axis point from the estimated axis.
    const double yaw = e.primitive.yaw_deg * M_PI / 180;
    const double perpendicular = std::abs(-(press.object.x_mm - e.primitive.x_mm) * std::sin(yaw) +
                                          (press.object.y_mm - e.primitive.y_mm) * std::cos(yaw));
    EXPECT_LT(perpendicular, 0.3) << press.name;
    EXPECT_NEAR(e.primitive.normal_force_N, press.object.normal_force_N, 0.05 * press.object.normal_force_N);
  }
  for (int i : {17, 18}) {
    ContactReconstructor r(Uskin());
    const ContactEstimate e = AtHold(Rig()[size_t(i)], &r);
    ASSERT_TRUE(e.ok);
    EXPECT_EQ(e.primitive.shape, ContactShape::kFlat);
    EXPECT_NEAR(e.primitive.normal_force_N, Rig()[size_t(i)].object.normal_force_N, 0.03 * Rig()[size_t(i)].object.normal_force_N);
  }
}

// One scan barely tells a thin rod's radius (chi^2 moves by < 1 between R = 1 and 3 mm); a
// hold's mean does (by tens). Reconstructed through the rig's rod presses to mid-hold, the
// 1 mm rods come out thinner than the 2.5 mm rods, each within a factor 1.7 of the truth
// (the 1 mm rods read 1.3-1.6 mm: the forward model's bias at that width). Fitted scan by
// scan (max_hold_scans = 1) the radius follows the noise: at the same mid-hold scan 1.0 and
// 3.4 mm for the 1 mm rods, 4.9 and 3.2 mm for the 2.5 mm rods.
TEST(ContactReconstruction, HoldAveragingSettlesARodsRadius) {
  double thickest_thin = 0, thinnest_thick = 1e9;
  for (int i : {12, 13, 14, 15}) {
    const auto& press = Rig()[size_t(i)];
    ContactReconstructor r(Uskin());
    const ContactEstimate e = AtHold(press, &r);
    ASSERT_TRUE(e.ok) << press.name << ": " << e.problem;
    ASSERT_EQ(e.primitive.shape, ContactShape::kCylinder) << press.name;
    EXPECT_GT(e.averaged_scans, 10) << press.name;
    EXPECT_LT(std::abs(std::log(e.primitive.radius_mm / press.object.radius_mm)), std::log(1.7))
        << press.name << ": R " << e.primitive.radius_mm;
    if (press.object.radius_mm < 2) thickest_thin = std::max(thickest_thin, e.primitive.radius_mm);
    else thinnest_thick = std::min(thinnest_thick, e.primitive.radius_mm);
  }
  EXPECT_LT(thickest_thin, thinnest_thick);
}

// On a rod press's ramp and release a scan hardly tells the radius; without the weak prior
// on log R the fit wandered to the ends of the plausible range (0.3 and 60 mm on press_15,
// a 2.5 mm rod) and the leader's presses of those objects failed (27 pressure-map fallbacks
// in that replay). Every scan of the rig's rod presses now reads a radius within 0.6-12 mm.
TEST(ContactReconstruction, LightScansDoNotSendTheRadiusToItsBounds) {
  for (int i : {12, 13, 14, 15}) {
    const auto& press = Rig()[size_t(i)];
    ContactReconstructor r(Uskin());
    for (size_t k = 0; k < press.scans.size(); ++k) {
      const ContactEstimate& e = r.Reconstruct(press.scans[k]);
      if (!e.ok || !e.contact || e.primitive.shape == ContactShape::kFlat) continue;
      EXPECT_GT(e.primitive.radius_mm, 0.6) << press.name << " scan " << k;
      EXPECT_LT(e.primitive.radius_mm, 12.0) << press.name << " scan " << k;
    }
  }
}

// An object keeps its size while it touches: on the loading ramp of a rod press a scan (or
// the mean of the few scans a slow ramp holds still) barely tells the radius, and the fit
// used to jump with the noise (press_14, a 2.5 mm rod: 0.74 -> 2.92 -> 4.47 mm between
// neighbouring scans, |d log R| up to 1.5), which the leader feels as a flickering contact
// width. The warm fit's radius prior now follows the last answer
// (ReconstructionOptions::radius_track_log_sigma): between warm-started answers the largest
// scan-to-scan |d log R| of a press stays below 0.3 on the rig's rod and sphere presses, and
// for the rods below a quarter of the untracked fit's. (A candidate that replaces the model,
// on a light first touch, is model selection and may still change the size.)
TEST(ContactReconstruction, RadiusHoldsStillWhileTheContactLoads) {
  ReconstructionOptions steady;  // fe.radius_tracking: steady (posterior widens the prior)
  steady.radius_track_posterior = false;
  ReconstructionOptions untracked;
  untracked.radius_track_log_sigma = 0;
  for (int i : {0, 3, 12, 13, 14, 15, 16, 19}) {
    const auto& press = Rig()[size_t(i)];
    auto largest_jump = [&](const ReconstructionOptions& options) {
      ContactReconstructor r(Uskin(), options);
      double largest = 0, last_log_r = std::nan("");
      for (const auto& scan : press.scans) {
        const ContactEstimate& e = r.Reconstruct(scan);
        // The warm fit's answers (a candidate that replaces the model is model selection).
        const bool sized =
            e.ok && e.contact && e.warm_started && !e.two_contacts && e.primitive.shape != ContactShape::kFlat;
        const double log_r = sized ? std::log(e.primitive.radius_mm) : std::nan("");
        if (std::isfinite(log_r) && std::isfinite(last_log_r)) largest = std::max(largest, std::abs(log_r - last_log_r));
        last_log_r = log_r;
      }
      return largest;
    };
    const double tracked = largest_jump(steady), free = largest_jump(untracked);
    // Measured: 0.06-0.26 tracked, 0.63-1.44 untracked.
    EXPECT_LT(tracked, 0.3) << press.name;
    if (press.object.shape == ContactShape::kCylinder) {
      EXPECT_LT(tracked, 0.25 * free) << press.name;
    }
  }
}

// fe.radius_tracking: posterior (ReconstructionOptions::radius_track_posterior). A light first
// touch hardly tells a thin rod's radius; the steady prior (sigma 0.15 in log R about the
// last answer) then lets each ramp scan move it only a little, and the rig's 1 mm rod
// press_13 crawled down from a 3 mm first guess through the whole ramp (2.1 mm at 0.54 N).
// With the prior widened by what the scans so far left open, the ramp's scans correct it.
TEST(ContactReconstruction, PosteriorTrackingLetsTheRampCorrectALightFirstTouch) {
  ReconstructionOptions posterior, steady;
  posterior.radius_track_posterior = true;
  steady.radius_track_posterior = false;
  const auto& press = Rig()[13];
  ASSERT_EQ(press.object.shape, ContactShape::kCylinder);
  auto ramp_error = [&](const ReconstructionOptions& options) {
    ContactReconstructor r(Uskin(), options);
    double sum = 0;
    int count = 0;
    for (size_t i = 0; i < press.scans.size() && press.t_s[i] <= sensors::PressProtocol().HoldMid_s(); ++i) {
      const ContactEstimate& e = r.Reconstruct(press.scans[i]);
      const double force_N = press.ObjectAt(press.t_s[i]).normal_force_N;
      const bool ramp = force_N >= 0.25 && force_N < 0.95 * press.object.normal_force_N;
      if (!ramp || !e.ok || e.primitive.shape != ContactShape::kCylinder) continue;
      sum += std::abs(std::log(e.primitive.radius_mm / press.object.radius_mm));
      ++count;
    }
    EXPECT_GT(count, 5);
    return count > 0 ? sum / count : 0.0;
  };
  // Mean |log(R / 1 mm)| over the ramp from 0.25 N; measured 0.93 steady (2.1-3.1 mm),
  // 0.08 posterior (0.82-1.45 mm).
  const double held = ramp_error(steady), widened = ramp_error(posterior);
  EXPECT_LT(widened, std::log(1.3));
  EXPECT_LT(widened, 0.5 * held);
}

// Objects of the rig's kinds at radii, places and forces it did not press, through the
// rig's protocol (0.3 s unloaded, 0.7 s ramp, then the hold) rendered by the calibrated
// model with 2-count noise: at 0.4 s into the hold the hold mean gives spheres' radii to
// 5 % and rods' to 30 % (0.8 mm read 0.92, 1.5 mm 1.19, 2 mm 1.91: a rod's width tells less),
// the force to 1 %, the axis or centre to 0.05 mm.
TEST(ContactReconstruction, UnseenObjectsThroughAPressSettleTheirRadius) {
  const sensors::SensorProfile& p = Uskin();
  sensors::TactileForwardModel model(p, p.forward_model);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0, 1);
  struct Case {
    ContactShape shape;
    double radius_mm, x_mm, y_mm, yaw_deg, force_N;
  };
  const Case cases[] = {{ContactShape::kSphere, 1.5, 1, -2, 0, 0.3},    {ContactShape::kSphere, 3.5, -3, 2, 0, 0.5},
                        {ContactShape::kSphere, 12, 2, 2, 0, 1.0},      {ContactShape::kSphere, 20, -1, 0, 0, 1.2},
                        {ContactShape::kSphere, 4, 6, -6, 0, 0.4},      {ContactShape::kCylinder, 0.8, 0, 1, 30, 0.4},
                        {ContactShape::kCylinder, 1.5, 0.5, 0, -60, 0.6}, {ContactShape::kCylinder, 2, 0, -2, 90, 0.5},
                        {ContactShape::kCylinder, 3.5, 1, 1, 15, 0.8},  {ContactShape::kCylinder, 5, 0, 0, 45, 1.0}};
  for (const Case& c : cases) {
    ContactPrimitive truth;
    truth.shape = c.shape;
    truth.radius_mm = c.radius_mm;
    truth.x_mm = c.x_mm;
    truth.y_mm = c.y_mm;
    truth.yaw_deg = c.yaw_deg;
    ContactReconstructor r(p);
    ContactEstimate e;
    for (int k = 0; k <= 140; ++k) {  // 100 Hz: 0.4 s into the hold
      const double t = 0.01 * k;
      truth.normal_force_N = c.force_N * (t < 0.3 ? 0.0 : std::min(1.0, (t - 0.3) / 0.7));
      Eigen::VectorXd reading;
      model.Predict(truth, &reading);
      for (Eigen::Index i = 0; i < reading.size(); ++i)
        reading[i] += n(rng) * 2 * sensors::NewtonsPerCount(p, int(i / 3), int(i % 3));
      e = r.Reconstruct(reading, std::vector<uint8_t>(16, 1));
    }
    const std::string what = std::string(sensors::ContactShapeName(c.shape)) + " R " + std::to_string(c.radius_mm);
    ASSERT_TRUE(e.ok) << what << ": " << e.problem;
    ASSERT_EQ(e.primitive.shape, c.shape) << what;
    EXPECT_GT(e.averaged_scans, 10) << what;
    EXPECT_NEAR(e.primitive.normal_force_N, c.force_N, 0.01 * c.force_N) << what;
    const double radius_error = std::abs(std::log(e.primitive.radius_mm / c.radius_mm));
    if (c.shape == ContactShape::kSphere) {
      EXPECT_LT(radius_error, std::log(1.05)) << what << ": R " << e.primitive.radius_mm;
      EXPECT_LT(std::hypot(e.primitive.x_mm - c.x_mm, e.primitive.y_mm - c.y_mm), 0.05) << what;
    } else {
      EXPECT_LT(radius_error, std::log(1.3)) << what << ": R " << e.primitive.radius_mm;
      const double yaw = e.primitive.yaw_deg * M_PI / 180;
      EXPECT_LT(std::abs(-(c.x_mm - e.primitive.x_mm) * std::sin(yaw) + (c.y_mm - e.primitive.y_mm) * std::cos(yaw)), 0.05)
          << what;
    }
  }
}

// The hold mean only spans scans that agree within noise: a contact that moves or presses
// harder starts it anew, and the estimate follows from that very scan.
TEST(ContactReconstruction, HoldAveragingRestartsWhenTheContactMoves) {
  sensors::TactileForwardModel model(Uskin(), Uskin().forward_model);
  ContactReconstructor r(Uskin());
  std::mt19937_64 rng(21);
  const std::vector<uint8_t> valid(16, 1);
  ContactPrimitive c;
  c.radius_mm = 4;
  c.normal_force_N = 0.6;
  c.x_mm = -1.0;
  c.y_mm = 0.5;
  auto scan = [&] {
    Eigen::VectorXd reading;
    model.Predict(c, &reading);
    return Noisy(reading, &rng);
  };
  ContactEstimate e;
  for (int s = 0; s < 30; ++s) e = r.Reconstruct(scan(), valid);
  EXPECT_GE(e.averaged_scans, 25);  // a false restart now and then is allowed (3 sigma)
  EXPECT_NEAR(e.primitive.x_mm, -1.0, 0.05);
  c.x_mm = 0.5;  // moved 1.5 mm
  e = r.Reconstruct(scan(), valid);
  EXPECT_EQ(e.averaged_scans, 1);
  EXPECT_NEAR(e.primitive.x_mm, 0.5, 0.25);
  for (int s = 0; s < 10; ++s) e = r.Reconstruct(scan(), valid);
  EXPECT_GE(e.averaged_scans, 8);
  c.normal_force_N = 0.7;  // pressed harder
  e = r.Reconstruct(scan(), valid);
  EXPECT_EQ(e.averaged_scans, 1);
  EXPECT_NEAR(e.primitive.normal_force_N, 0.7, 0.035);
}

TEST(ContactReconstruction, StrokingShearIsRecovered) {
  for (int i : {19, 20}) {
    const auto& press = Rig()[size_t(i)];
    ContactReconstructor r(Uskin());
    const ContactEstimate e = AtHold(press, &r);
    ASSERT_TRUE(e.ok);
    EXPECT_NEAR(e.primitive.shear_x_N, press.object.shear_x_N, 0.02);
    EXPECT_NEAR(e.primitive.shear_y_N, press.object.shear_y_N, 0.02);
  }
}

TEST(ContactReconstruction, ContactAppearingAndVanishing) {
  const auto& press = Rig()[3];
  ContactReconstructor r(Uskin());
  std::vector<int> contact;
  for (const auto& s : press.scans) contact.push_back(r.Reconstruct(s).contact);
  EXPECT_FALSE(contact.front());
  EXPECT_TRUE(contact[110]);
  // One contact episode: it appears once during the ramp and never flickers (the log ends
  // as the release reaches zero, so the last scan may still carry a few mN).
  int rises = 0, falls = 0;
  for (size_t i = 1; i < contact.size(); ++i) rises += contact[i] && !contact[i - 1], falls += !contact[i] && contact[i - 1];
  EXPECT_EQ(rises, 1);
  EXPECT_LE(falls, 1);
  EXPECT_EQ(r.counters().fallbacks, 0);
  EXPECT_GT(r.counters().no_contact, 25);
}

TEST(ContactReconstruction, SlidingAcrossTaxelBoundariesHasNoJumps) {
  sensors::TactileForwardModel model(Uskin(), Uskin().forward_model);
  ContactReconstructor r(Uskin());
  std::mt19937_64 rng(7);
  std::vector<uint8_t> valid(16, 1);
  double last_x = std::nan("");
  for (int step = 0; step <= 80; ++step) {
    ContactPrimitive c;
    c.radius_mm = 4;
    c.normal_force_N = 0.6;
    c.x_mm = -4.0 + 0.1 * step;  // crosses the taxel boundaries at x = -2.35, 0, 2.35
    c.y_mm = 1.0;
    Eigen::VectorXd reading;
    model.Predict(c, &reading);
    const ContactEstimate& e = r.Reconstruct(Noisy(reading, &rng), valid);
    ASSERT_TRUE(e.ok) << "step " << step << ": " << e.problem;
    if (std::isfinite(last_x)) {
      EXPECT_LT(std::abs(e.primitive.x_mm - last_x), 0.1 + 0.25) << "step " << step;
    }
    EXPECT_NEAR(e.primitive.x_mm, c.x_mm, 0.25);
    last_x = e.primitive.x_mm;
  }
  EXPECT_GT(r.counters().warm_fits, 60);  // the warm start carries a moving contact
}

// Two spheres pressed at once (two fingertips, two bumps): the pair model finds both, with
// each one's position and force, within a short hold of noisy scans.
TEST(ContactReconstruction, TwoSimultaneousContactsAreTwoSpheres) {
  const ContactPrimitive a = SphereAt(-5, -4, 2.5, 0.5), b = SphereAt(4, 5, 4, 0.3);
  std::mt19937_64 rng(7);
  ContactReconstructor r(Uskin());
  const ContactEstimate e = HeldFor(&r, ReadingsOf({a, b}), &rng);
  ASSERT_TRUE(e.ok) << e.problem;
  ASSERT_TRUE(e.two_contacts) << ContactShapeName(e.primitive.shape) << " R " << e.primitive.radius_mm;
  // Which sphere is "first" is the fit's choice.
  const bool swapped = e.primitive.x_mm > e.second.x_mm;
  const ContactPrimitive& ea = swapped ? e.second : e.primitive;
  const ContactPrimitive& eb = swapped ? e.primitive : e.second;
  EXPECT_NEAR(ea.x_mm, a.x_mm, 0.3);
  EXPECT_NEAR(ea.y_mm, a.y_mm, 0.3);
  EXPECT_NEAR(eb.x_mm, b.x_mm, 0.3);
  EXPECT_NEAR(eb.y_mm, b.y_mm, 0.3);
  EXPECT_NEAR(ea.normal_force_N, a.normal_force_N, 0.05);
  EXPECT_NEAR(eb.normal_force_N, b.normal_force_N, 0.05);
  EXPECT_NEAR(e.normal_force_N(), 0.8, 0.02);
  EXPECT_LT(e.rms_sigma, 1.5);
  EXPECT_GT(r.counters().two_contacts, 0);
}

// A press's ramp changes the force, not the shape: the force step (one Gauss-Newton step in
// the force and shear, 3 evaluations) answers most ramp scans as well as the full warm fit,
// for fewer evaluations, and the force tracks the truth as closely.
TEST(ContactReconstruction, ForceStepTracksARampWithFewerEvaluations) {
  sensors::TactileForwardModel model(Uskin(), Uskin().forward_model);
  ReconstructionOptions without;
  without.force_step_first = false;
  ContactReconstructor with_step(Uskin()), full(Uskin(), without);
  std::mt19937_64 rng(3);
  double worst_with = 0, worst_full = 0;
  int fewest_on_a_step = 1000, steps_alone = 0;
  ContactEstimate a, b;
  for (int scan = 0; scan < 80; ++scan) {
    const ContactPrimitive c = SphereAt(1, -1, 5, 0.1 + 0.01 * scan);  // 1.25 %/scan at the end
    Eigen::VectorXd reading;
    model.Predict(c, &reading);
    const Eigen::VectorXd noisy = Noisy(reading, &rng);
    const int64_t steps_before = with_step.counters().force_steps;
    a = with_step.Reconstruct(noisy, std::vector<uint8_t>(16, 1));
    if (with_step.counters().force_steps > steps_before) {
      fewest_on_a_step = std::min(fewest_on_a_step, a.evaluations);
      steps_alone += a.evaluations == 2;
    }
    b = full.Reconstruct(noisy, std::vector<uint8_t>(16, 1));
    ASSERT_TRUE(a.ok && b.ok) << "scan " << scan;
    if (scan >= 10) {
      worst_with = std::max(worst_with, std::abs(a.primitive.normal_force_N / c.normal_force_N - 1));
      worst_full = std::max(worst_full, std::abs(b.primitive.normal_force_N / c.normal_force_N - 1));
    }
  }
  // Measured: 36 of the 80 scans by the force step, 981 evaluations against 1285; the worst
  // force error from scan 10 on (0.2 N) 3.1 % with and without it (the noise's).
  EXPECT_GT(with_step.counters().force_steps, 25);
  EXPECT_EQ(full.counters().force_steps, 0);
  EXPECT_LT(with_step.counters().evaluations, 0.85 * full.counters().evaluations);
  EXPECT_LT(worst_with, 0.05);
  EXPECT_LT(worst_with, worst_full + 0.01);
  EXPECT_NEAR(a.primitive.radius_mm, 5.0, 0.5);
  EXPECT_NEAR(a.primitive.x_mm, 1.0, 0.1);
  // The last answer's parts are kept: a scan answered by the force step alone evaluates
  // its log R difference and the step, not the point it starts from (3 without that).
  EXPECT_EQ(fewest_on_a_step, 2);
  EXPECT_GT(steps_alone, 10);
}

// A slow ramp holds still for 2-4 scans at a time; the force step answers such short hold
// means too (ReconstructionOptions::force_step_max_averaged_scans): fewer evaluations over
// the rig's rod presses, the same answer at the hold.
TEST(ContactReconstruction, ShortHoldMeansTakeTheForceStep) {
  ReconstructionOptions single_scans_only;
  single_scans_only.force_step_max_averaged_scans = 1;
  int64_t with_short = 0, without = 0;
  for (int i : {12, 14, 15}) {
    const auto& press = Rig()[size_t(i)];
    ContactReconstructor a(Uskin()), b(Uskin(), single_scans_only);
    const ContactEstimate ea = AtHold(press, &a), eb = AtHold(press, &b);
    ASSERT_TRUE(ea.ok && eb.ok) << press.name;
    EXPECT_NEAR(ea.primitive.normal_force_N, eb.primitive.normal_force_N, 0.01 * eb.primitive.normal_force_N) << press.name;
    EXPECT_LT(std::abs(std::log(ea.primitive.radius_mm / press.object.radius_mm)), std::log(1.7)) << press.name;
    with_short += a.counters().evaluations;
    without += b.counters().evaluations;
  }
  EXPECT_LT(with_short, 0.9 * without);
}

// Broyden's secant update between finite-difference Jacobians: the same ramp (force up
// 1.25 %/scan) and a sphere moving 20 um a scan, read with far fewer forward-model
// evaluations and the same accuracy. Measured: 738 evaluations against 1068, worst force
// error from scan 10 on 2.5 % both, worst x error 0.068 against 0.057 mm, R 5.95 mm.
// (With explained scans' candidates stopped before evaluations past their budget: 496
// against 601, against 761 without that cap, as a differences Jacobian costs 3 of their 6.)
TEST(ContactReconstruction, BroydenJacobianFitsWithFewerEvaluations) {
  sensors::TactileForwardModel model(Uskin(), Uskin().forward_model);
  ReconstructionOptions differences;
  differences.jacobian_refresh = 1;
  ContactReconstructor broyden(Uskin()), every(Uskin(), differences);
  EXPECT_EQ(broyden.options().jacobian_refresh, 4);
  std::mt19937_64 rng(5);
  double worst_force[2] = {0, 0}, worst_x[2] = {0, 0};
  ContactEstimate a, b;
  for (int scan = 0; scan < 80; ++scan) {
    const double x_mm = 0.5 + 0.02 * scan;
    const ContactPrimitive c = SphereAt(x_mm, -1, 6, 0.1 + 0.01 * scan);
    Eigen::VectorXd reading;
    model.Predict(c, &reading);
    const Eigen::VectorXd noisy = Noisy(reading, &rng);
    a = broyden.Reconstruct(noisy, std::vector<uint8_t>(16, 1));
    b = every.Reconstruct(noisy, std::vector<uint8_t>(16, 1));
    ASSERT_TRUE(a.ok && b.ok) << "scan " << scan;
    if (scan >= 10) {
      worst_force[0] = std::max(worst_force[0], std::abs(a.primitive.normal_force_N / c.normal_force_N - 1));
      worst_force[1] = std::max(worst_force[1], std::abs(b.primitive.normal_force_N / c.normal_force_N - 1));
      worst_x[0] = std::max(worst_x[0], std::abs(a.primitive.x_mm - x_mm));
      worst_x[1] = std::max(worst_x[1], std::abs(b.primitive.x_mm - x_mm));
    }
  }
  EXPECT_LT(broyden.counters().evaluations, 0.9 * every.counters().evaluations)
      << broyden.counters().evaluations << " vs " << every.counters().evaluations;
  EXPECT_LT(worst_force[0], 0.05);
  EXPECT_LT(worst_force[0], worst_force[1] + 0.01);
  EXPECT_LT(worst_x[0], 0.1);
  EXPECT_LT(worst_x[0], worst_x[1] + 0.03);
  EXPECT_NEAR(a.primitive.radius_mm, 6.0, 0.6);
}

// An edge that ends on the pad (a 9 mm rod of radius 1 mm, yaw 20, centred at (1, -2)) is a
// finite rod: its length, centre and yaw found from a held press; without the finite-rod
// model the crossing rod cannot explain it (fallback or a poorer fit).
TEST(ContactReconstruction, AnEdgeIsARodOfFiniteLength) {
  sensors::TactileForwardModel model(Uskin(), Uskin().forward_model);
  ContactPrimitive c;
  c.shape = ContactShape::kCylinder;
  c.radius_mm = 1;
  c.length_mm = 9;
  c.yaw_deg = 20;
  c.x_mm = 1;
  c.y_mm = -2;
  c.normal_force_N = 0.6;
  Eigen::VectorXd reading;
  model.Predict(c, &reading);
  std::mt19937_64 rng(5);
  ContactReconstructor r(Uskin());
  const ContactEstimate e = HeldFor(&r, reading, &rng);
  ASSERT_TRUE(e.ok) << e.problem;
  ASSERT_EQ(e.primitive.shape, ContactShape::kCylinder);
  EXPECT_NEAR(e.primitive.length_mm, 9.0, 1.0);
  EXPECT_NEAR(e.primitive.x_mm, 1.0, 0.3);
  EXPECT_NEAR(e.primitive.y_mm, -2.0, 0.3);
  EXPECT_NEAR(e.primitive.yaw_deg, 20.0, 3.0);
  EXPECT_NEAR(e.primitive.normal_force_N, 0.6, 0.02);
  EXPECT_LT(e.rms_sigma, 1.5);

  ReconstructionOptions crossing_only;
  crossing_only.fit_finite_rods = false;
  ContactReconstructor r2(Uskin(), crossing_only);
  rng.seed(5);
  const ContactEstimate e2 = HeldFor(&r2, reading, &rng);
  EXPECT_EQ(e2.primitive.length_mm, 0.0);
  EXPECT_TRUE(!e2.ok || e2.rms_sigma > 2 * e.rms_sigma) << e2.rms_sigma << " vs " << e.rms_sigma;
}

// Without the pair model, one primitive cannot explain two contacts: a fallback (the
// pressure map takes over), counted, not a guess.
TEST(ContactReconstruction, TwoContactsWithoutThePairModelAreAFallbackNotAGuess) {
  const ContactPrimitive a = SphereAt(-5, -5, 2.5, 0.5), b = SphereAt(5, 5, 2.5, 0.5);
  ReconstructionOptions options;
  options.fit_pairs = false;
  ContactReconstructor r(Uskin(), options);
  const ContactEstimate& e = r.Reconstruct(ReadingsOf({a, b}), std::vector<uint8_t>(16, 1));
  EXPECT_TRUE(e.contact);
  EXPECT_FALSE(e.ok);
  EXPECT_FALSE(e.two_contacts);
  EXPECT_EQ(r.counters().fallbacks, 1);
}

// One contact is not split in two: a sphere, a rod across the pad and a flat, each held,
// stay single primitives (the pair's four extra unknowns must buy more than they cost, and
// its spheres must be apart and each carry a share).
TEST(ContactReconstruction, OneContactIsNotReadAsTwo) {
  sensors::TactileForwardModel model(Uskin(), Uskin().forward_model);
  std::vector<ContactPrimitive> objects(3);
  objects[0].radius_mm = 8;
  objects[0].normal_force_N = 0.8;
  objects[0].x_mm = 1;
  objects[1].shape = ContactShape::kCylinder;
  objects[1].radius_mm = 1;
  objects[1].yaw_deg = 30;
  objects[1].normal_force_N = 0.6;
  objects[2].shape = ContactShape::kFlat;
  objects[2].normal_force_N = 1.0;
  std::mt19937_64 rng(11);
  for (const ContactPrimitive& c : objects) {
    Eigen::VectorXd reading;
    model.Predict(c, &reading);
    ContactReconstructor r(Uskin());
    const ContactEstimate e = HeldFor(&r, reading, &rng);
    ASSERT_TRUE(e.ok) << ContactShapeName(c.shape) << ": " << e.problem;
    EXPECT_FALSE(e.two_contacts) << ContactShapeName(c.shape);
    EXPECT_EQ(e.primitive.shape, c.shape);
    EXPECT_EQ(e.primitive.length_mm, 0.0) << ContactShapeName(c.shape);  // the rod crosses the pad
    EXPECT_EQ(r.counters().two_contacts, 0) << ContactShapeName(c.shape);
  }
}

TEST(ContactReconstruction, SaturatedTaxelsAreHardContactNotMissing) {
  // A profile whose normal channel saturates at 0.1 N per taxel.
  sensors::SensorProfile p = Uskin();
  p.calibration.saturation_high_counts = 1200;  // (1200 - 1000) * 0.0005 N = 0.1 N
  sensors::TactileForwardModel model(p, p.forward_model);
  ContactPrimitive c;
  c.radius_mm = 5;
  c.normal_force_N = 0.8;  // inner taxels read ~0.13 N: saturated
  Eigen::VectorXd reading;
  model.Predict(c, &reading);
  std::vector<uint8_t> valid(16, 1), saturated(16, 0);
  for (int k = 0; k < 16; ++k)
    if (reading[3 * k + 2] >= 0.1) {
      saturated[size_t(k)] = 1;
      valid[size_t(k)] = 0;
      reading.segment(3 * k, 3).setZero();  // what the assembler leaves in an invalid taxel
    }
  ASSERT_GE(std::count(saturated.begin(), saturated.end(), 1), 4);
  ContactReconstructor as_saturated(p), as_missing(p);
  const ContactEstimate e = as_saturated.Reconstruct(reading, valid, saturated);
  const ContactEstimate m = as_missing.Reconstruct(reading, valid, {});
  ASSERT_TRUE(e.contact);
  // Full scale is a lower bound: the force estimate never drops below what saturation implies.
  EXPECT_GT(e.primitive.normal_force_N, 0.6);
  EXPECT_EQ(as_saturated.counters().saturated_taxels, std::count(saturated.begin(), saturated.end(), 1));
  (void)m;
}

TEST(ContactReconstruction, NanScansNeverReachTheFit) {
  sensors::TactileForwardModel model(Uskin(), Uskin().forward_model);
  ContactPrimitive c;
  c.radius_mm = 5;
  c.normal_force_N = 0.5;
  Eigen::VectorXd reading;
  model.Predict(c, &reading);
  reading[3 * 5 + 2] = std::nan("");
  reading[3 * 12] = std::numeric_limits<double>::infinity();
  ContactReconstructor r(Uskin());
  const ContactEstimate& e = r.Reconstruct(reading, std::vector<uint8_t>(16, 1));
  EXPECT_TRUE(e.ok) << e.problem;
  EXPECT_TRUE(std::isfinite(e.primitive.normal_force_N));
  EXPECT_NEAR(e.primitive.normal_force_N, 0.5, 0.05);
  Eigen::VectorXd all_nan = Eigen::VectorXd::Constant(48, std::nan(""));
  const ContactEstimate& f = r.Reconstruct(all_nan, std::vector<uint8_t>(16, 1));
  EXPECT_FALSE(f.ok);
  EXPECT_EQ(r.counters().fallbacks, 1);
}

TEST(ContactReconstruction, DivergingFitFallsBackAndIsCounted) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  Eigen::VectorXd garbage(48);
  for (Eigen::Index i = 0; i < 48; ++i) garbage[i] = u(rng);
  for (int k = 0; k < 16; ++k) garbage[3 * k + 2] = std::abs(garbage[3 * k + 2]);  // it "presses"
  ContactReconstructor r(Uskin());
  const ContactEstimate& e = r.Reconstruct(garbage, std::vector<uint8_t>(16, 1));
  EXPECT_TRUE(e.contact);
  EXPECT_FALSE(e.ok);
  EXPECT_FALSE(e.problem.empty());
  EXPECT_EQ(r.counters().fallbacks, 1);
}

TEST(ContactReconstruction, NeedsACalibratedProfile) {
  sensors::SensorProfile p = Uskin();
  p.has_forward_model = false;
  EXPECT_THROW(ContactReconstructor{p}, std::invalid_argument);
}

TEST(ContactReconstruction, RejectsOptionsThatCannotWork) {
  auto with = [](auto change) {
    ReconstructionOptions o;
    change(o);
    return o;
  };
  EXPECT_NO_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.max_hold_scans = 1; })));
  EXPECT_NO_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.radius_prior_log_sigma = 0; })));
  EXPECT_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.max_hold_scans = 0; })),
               std::invalid_argument);
  EXPECT_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.hold_change_sigma = std::nan(""); })),
               std::invalid_argument);
  EXPECT_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.min_radius_mm = 0; })),
               std::invalid_argument);
  EXPECT_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.radius_prior_mm = -1; })),
               std::invalid_argument);
  EXPECT_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.jacobian_refresh = 0; })),
               std::invalid_argument);
  EXPECT_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.cells_per_evaluation = 0; })),
               std::invalid_argument);
  EXPECT_NO_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.jacobian_refresh = 1; })));
  EXPECT_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.dead_reading_share = 1; })),
               std::invalid_argument);
  EXPECT_NO_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.dead_reading_share = 0; })));
  EXPECT_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.min_pair_force_share = 0.6; })),
               std::invalid_argument);
  EXPECT_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.min_rod_length_mm = 0; })),
               std::invalid_argument);
  EXPECT_THROW(
      ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.explained_candidate_evaluations = -1; })),
      std::invalid_argument);
  EXPECT_NO_THROW(
      ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.explained_candidate_evaluations = 0; })));
  EXPECT_NO_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.radius_track_log_sigma = 0; })));
  EXPECT_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.radius_track_log_sigma = std::nan(""); })),
               std::invalid_argument);
  EXPECT_NO_THROW(
      ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.force_step_max_averaged_scans = 1; })));
  EXPECT_THROW(ContactReconstructor(Uskin(), with([](ReconstructionOptions& o) { o.force_step_max_averaged_scans = 0; })),
               std::invalid_argument);
}

// While the model explains the scans, a candidate whose one iteration costs more than the
// scan's check waits (defer_costly_candidates): on the rig's press_10 (an 8 mm sphere) a rod
// candidate grown over the pad took 20-26 budget units a scan against a check of 6, 0.5-1 ms
// of reconstruction. A new candidate's cost is not known until it is evaluated, and one
// whose LM trial grows its patch learns it too late: on press_09 (a 15 mm sphere) a fresh
// rod candidate's first iteration took 23 units in an explained scan. So such a candidate
// also stops before an evaluation (its cost estimated from the patch) that would take it
// past the check and one cheap iteration: no explained scan's candidate costs more than 10.
// What deferral saves is what large patches cost: an explained scan's units beyond one per
// evaluation (a grown rod's 3-7 a trial). That must fall, the model stay the same. (The
// explained scans' dearest total cost also counts cheap evaluations within the scan's budget
// -- warm fit 24, check 6 -- which the model can push to that ceiling in both modes alike:
// with the rod band at 0.3 mm, press_10's ramp scan 45 takes 28 one-unit evaluations either
// way, while only the eager run pays 19 units beyond its 9 evaluations at scan 53.)
TEST(ContactReconstruction, AnExpensiveCandidateWaitsWhileTheModelExplainsTheScans) {
  struct Run {
    int dearest_explained = 0, evaluations = 0;  // dearest: units beyond one per evaluation
    ContactEstimate at_hold;
  };
  auto run = [](const ReconstructionOptions& o, int i_press) {
    Run out;
    ContactReconstructor r(Uskin(), o);
    const sensors::CalibrationPress& press = Rig()[size_t(i_press)];
    const double t_hold = sensors::PressProtocol().HoldMid_s();
    for (size_t i = 0; i < press.scans.size(); ++i) {
      const ContactEstimate& e = r.Reconstruct(press.scans[i]);
      out.evaluations += e.evaluations;
      if (e.warm_started && e.ok && e.rms_sigma <= o.settle_rms_sigma)
        out.dearest_explained = std::max(out.dearest_explained, e.evaluation_cost - e.evaluations);
      if (press.t_s[i] <= t_hold) out.at_hold = e;
    }
    return out;
  };
  for (int i_press : {9, 10}) {
    ReconstructionOptions o;
    const Run deferred = run(o, i_press);
    o.defer_costly_candidates = false;
    const Run eager = run(o, i_press);
    const std::string name = Rig()[size_t(i_press)].name;
    EXPECT_LT(deferred.dearest_explained, eager.dearest_explained) << name;
    EXPECT_LT(deferred.evaluations, eager.evaluations) << name;
    ASSERT_TRUE(deferred.at_hold.ok) << name;
    EXPECT_EQ(deferred.at_hold.primitive.shape, eager.at_hold.primitive.shape) << name;
    EXPECT_NEAR(deferred.at_hold.primitive.radius_mm, eager.at_hold.primitive.radius_mm,
                0.05 * eager.at_hold.primitive.radius_mm)
        << name;
    RecordProperty("dearest_explained_cost_" + name, std::to_string(deferred.dearest_explained) + " (eager: " +
                                                         std::to_string(eager.dearest_explained) + ")");
  }
}

}  // namespace
}  // namespace sedbridge::contact

namespace sedbridge::contact {
namespace {

// Objects the rig did not press: random spheres, rods and flats over the pad at random
// forces, rendered by the calibrated forward model with 2-count noise, reconstructed from
// the same object held for `scans` scans (1: a cold single scan with full model selection;
// 40: the bridge's default amortized selection, one candidate start at a time within a
// budget of evaluations per scan).
void UnseenObjects(ModelSelection selection, int scans) {
  sensors::TactileForwardModel model(Uskin(), Uskin().forward_model);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  int shape_right = 0, cases = 0;
  for (int i = 0; i < 36; ++i) {
    ContactPrimitive c;
    c.shape = i % 3 == 0 ? ContactShape::kSphere : i % 3 == 1 ? ContactShape::kCylinder : ContactShape::kFlat;
    c.normal_force_N = 0.2 + 1.2 * u(rng);
    if (c.shape == ContactShape::kSphere) {
      c.radius_mm = 2 + 13 * u(rng);
      c.x_mm = -6 + 12 * u(rng);
      c.y_mm = -6 + 12 * u(rng);
    } else if (c.shape == ContactShape::kCylinder) {
      c.radius_mm = 0.5 + 2.5 * u(rng);
      c.yaw_deg = -90 + 180 * u(rng);
      const double s = -4 + 8 * u(rng), yaw = c.yaw_deg * M_PI / 180;
      c.x_mm = -s * std::sin(yaw);
      c.y_mm = s * std::cos(yaw);
    }
    Eigen::VectorXd reading;
    model.Predict(c, &reading);
    ReconstructionOptions options;
    options.selection = selection;
    ContactReconstructor r(Uskin(), options);
    const ContactEstimate e = HeldFor(&r, reading, &rng, scans);
    ++cases;
    ASSERT_TRUE(e.ok) << i << ": " << e.problem;
    EXPECT_NEAR(e.primitive.normal_force_N, c.normal_force_N, 0.05 * c.normal_force_N) << i;
    if (e.primitive.shape != c.shape) continue;
    ++shape_right;
    if (c.shape == ContactShape::kSphere) {
      EXPECT_LT(std::hypot(e.primitive.x_mm - c.x_mm, e.primitive.y_mm - c.y_mm), 0.5) << i;
      EXPECT_NEAR(e.primitive.radius_mm, c.radius_mm, 0.35 * c.radius_mm) << i;
    } else if (c.shape == ContactShape::kCylinder) {
      EXPECT_LT(std::abs(std::remainder(e.primitive.yaw_deg - c.yaw_deg, 180.0)), 5.0) << i;
    }
  }
  // Large spheres and thick rods can look alike on a 4.7 mm grid; most must be told apart.
  EXPECT_GE(shape_right, cases * 8 / 10);
}

TEST(ContactReconstruction, UnseenObjectsFromOneNoisyScan) { UnseenObjects(ModelSelection::kFull, 1); }
TEST(ContactReconstruction, UnseenObjectsHeldForFortyScans) { UnseenObjects(ModelSelection::kAmortized, 40); }

// Amortized selection spreads the model selection over scans: on the same held object it
// must end where the full selection of one scan ends (same shape, same force and position),
// within 40 scans (0.4 s at 100 Hz).
TEST(ContactReconstruction, AmortizedSelectionReachesTheFullSelectionsModel) {
  sensors::TactileForwardModel model(Uskin(), Uskin().forward_model);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  int same_shape = 0, cases = 0;
  for (int i = 0; i < 24; ++i) {
    ContactPrimitive c;
    c.shape = i % 3 == 0 ? ContactShape::kSphere : i % 3 == 1 ? ContactShape::kCylinder : ContactShape::kFlat;
    c.normal_force_N = 0.2 + 1.0 * u(rng);
    c.radius_mm = c.shape == ContactShape::kSphere ? 2 + 10 * u(rng) : 0.6 + 2.4 * u(rng);
    c.yaw_deg = -90 + 180 * u(rng);
    c.x_mm = -4 + 8 * u(rng);
    c.y_mm = c.shape == ContactShape::kCylinder ? 0 : -4 + 8 * u(rng);
    Eigen::VectorXd reading;
    model.Predict(c, &reading);
    const std::vector<uint8_t> valid(16, 1);
    ReconstructionOptions full_options;
    full_options.selection = ModelSelection::kFull;
    ContactReconstructor full(Uskin(), full_options), amortized(Uskin());
    std::mt19937_64 noise(100 + i);
    const Eigen::VectorXd scan = Noisy(reading, &noise);
    const ContactEstimate f = full.Reconstruct(scan, valid);
    ContactEstimate a;
    for (int s = 0; s < 40; ++s) a = amortized.Reconstruct(scan, valid);
    if (!f.ok) continue;
    ++cases;
    ASSERT_TRUE(a.ok) << i << ": " << a.problem;
    if (a.primitive.shape != f.primitive.shape) continue;
    ++same_shape;
    EXPECT_NEAR(a.primitive.normal_force_N, f.primitive.normal_force_N, 0.02 * f.primitive.normal_force_N) << i;
    EXPECT_LT(a.rms_sigma, f.rms_sigma + 0.05) << i;
    if (c.shape == ContactShape::kSphere && a.primitive.shape == ContactShape::kSphere) {
      EXPECT_LT(std::hypot(a.primitive.x_mm - f.primitive.x_mm, a.primitive.y_mm - f.primitive.y_mm), 0.1) << i;
    }
  }
  EXPECT_GE(cases, 20);
  EXPECT_GE(same_shape, cases * 9 / 10);
}

// The point of the amortized selection: no scan pays for a whole model selection. Through
// rig presses (sphere, 1 mm rod, flat, stroke), from first touch to release, each scan's
// forward-model evaluations stay within the two budgets plus the first-touch share and
// one LM iteration's overrun (a sphere/rod iteration: 4 for the Jacobian + 1, plus
// rejected trial steps).
TEST(ContactReconstruction, AmortizedScanCostIsBounded) {
  const ReconstructionOptions o;
  const int bound = 2 * o.warm_scan_evaluations + o.candidate_scan_evaluations + 2 * 15;
  for (int i : {3, 12, 15, 17, 19}) {
    ContactReconstructor r(Uskin());
    int most = 0;
    for (const auto& s : Rig()[size_t(i)].scans) most = std::max(most, r.Reconstruct(s).evaluations);
    EXPECT_LE(most, bound) << Rig()[size_t(i)].name;
    EXPECT_GT(most, 0) << Rig()[size_t(i)].name;
  }
}

// While the current model explains the scan within settle_rms_sigma, exploring is a check:
// the candidate gets explained_candidate_evaluations (6) a scan instead of 12, so those
// scans cost less (the per-scan p99 of the reconstruction on the rig's flat fell from 1.9
// to 0.5 ms in reconstruction_benchmark; fidelity unchanged). With Broyden updates a
// candidate's iteration costs one evaluation but each scan's continuation starts with a
// finite-difference Jacobian, so the dearest scan is no longer the measure: the explained
// scans' total is.
TEST(ContactReconstruction, ExplainedScansExploreWithASmallerBudget) {
  // The rig's flat (press_17): its warm fit costs one evaluation, so the candidate's budget
  // is what its explained scans spend.
  auto spent_when_explained = [](const ReconstructionOptions& o) {
    int spent = 0;
    ContactReconstructor r(Uskin(), o);
    for (const auto& s : Rig()[17].scans) {
      const ContactEstimate& e = r.Reconstruct(s);
      if (e.warm_started && e.ok && e.rms_sigma <= o.settle_rms_sigma) spent += e.evaluations;
    }
    return spent;
  };
  ReconstructionOptions o;
  const int small = spent_when_explained(o);
  o.explained_candidate_evaluations = 0;
  const int full = spent_when_explained(o);
  EXPECT_LT(small, full);
  RecordProperty("evaluations", std::to_string(small) + " (candidate budget 12: " + std::to_string(full) + ")");
}

// A dead taxel under a sphere that taxel health has not masked yet (it reads nothing, its
// neighbours are loaded): the fit that would fall back is redone without it (the lone
// misfit) and kept out of the later scans (else the next warm fit carries its misfit again
// and two spheres either side of it replace the contact), and the sphere is where it was.
// Off (lone_taxel_share 0) the scan falls back. The
// same sphere with every taxel live leaves none out: a contact on one taxel's centre is
// evidence its neighbours confirm, not a lone misfit.
TEST(ContactReconstruction, ALoneLyingTaxelIsLeftOutOfTheFitNotTheContact) {
  const int k = 5;
  const auto& t = Uskin().taxels[size_t(k)];
  const Eigen::VectorXd healthy = ReadingsOf({SphereAt(t.x_mm, t.y_mm, 5.0, 0.8)});
  Eigen::VectorXd dead = healthy;
  dead.segment(3 * k, 3).setZero();
  for (double share : {0.5, 0.0}) {
    ReconstructionOptions options;
    options.lone_taxel_share = share;
    ContactReconstructor r(Uskin(), options);
    std::mt19937_64 rng(3);
    const ContactEstimate e = HeldFor(&r, dead, &rng, 40);
    SCOPED_TRACE("lone_taxel_share " + std::to_string(share) + ": " + e.problem);
    if (share == 0) {
      EXPECT_FALSE(e.ok);
      continue;
    }
    ASSERT_TRUE(e.ok);
    ASSERT_EQ(e.taxel_use.size(), 16u);
    EXPECT_EQ(e.taxel_use[size_t(k)], TaxelUse::kLoneMisfit);
    EXPECT_EQ(e.taxels_used, 15);
    EXPECT_GT(r.counters().lone_taxels_left_out, 0);
    EXPECT_GT(r.counters().lone_taxel_scans, 30);  // left out of the later scans too
    EXPECT_LT(std::hypot(e.primitive.x_mm - t.x_mm, e.primitive.y_mm - t.y_mm), 0.3);
    EXPECT_NEAR(e.primitive.normal_force_N, 0.8, 0.08);
  }
  ContactReconstructor r(Uskin());
  std::mt19937_64 rng(3);
  const ContactEstimate e = HeldFor(&r, healthy, &rng, 40);
  ASSERT_TRUE(e.ok) << e.problem;
  EXPECT_EQ(e.taxels_used, 16);
  EXPECT_EQ(r.counters().lone_taxels_left_out, 0);
}


// A rig press with taxel k dead from the first scan (it repeats its readings of the quiet
// scans before the contact), reconstructed to the middle of the hold.
ContactEstimate WithDeadTaxelAtHold(const sensors::CalibrationPress& press, int k, ContactReconstructor* r) {
  const size_t quiet = 30;  // the protocol's unloaded 0.3 s at 100 Hz
  const double t_hold = sensors::PressProtocol().HoldMid_s();
  ContactEstimate e;
  for (size_t i = 0; i < press.readings_N.size() && press.t_s[i] <= t_hold; ++i) {
    Eigen::VectorXd readings = press.readings_N[i];
    readings.segment(3 * k, 3) = press.readings_N[i % quiet].segment(3 * k, 3);
    e = r->Reconstruct(readings, std::vector<uint8_t>(16, 1));
  }
  return e;
}

// A fit that bent around a dead taxel while the press loaded (rig press_04, a 5 mm sphere
// between taxels 5 and 9, taxel 5 dead: a 0.3 mm sphere beside taxel 9) carries its misfit on
// the live taxels beside it, not on the dead one: the dead one is the taxel that reads most
// below the fit, and the refit without it explains the others (its misfit stands alone).
// A rod that ended short of a dead taxel at its end (press_13, taxel 1) is refitted as the
// rod across the pad.
TEST(ContactReconstruction, ADeadTaxelTheFitBentAroundIsLeftOut) {
  struct Case {
    int press, taxel;
    ContactShape shape;
  };
  for (const Case& c : {Case{4, 5, ContactShape::kSphere}, Case{13, 1, ContactShape::kCylinder}}) {
    SCOPED_TRACE("press_" + std::to_string(c.press) + ", taxel " + std::to_string(c.taxel) + " dead");
    const sensors::CalibrationPress& press = Rig()[size_t(c.press)];
    ContactReconstructor r(Uskin());
    const ContactEstimate e = WithDeadTaxelAtHold(press, c.taxel, &r);
    ASSERT_TRUE(e.ok) << e.problem;
    ASSERT_EQ(e.taxel_use.size(), 16u);
    EXPECT_EQ(e.taxel_use[size_t(c.taxel)], TaxelUse::kLoneMisfit);
    EXPECT_EQ(e.primitive.shape, c.shape) << ContactShapeName(e.primitive.shape);
    EXPECT_LT(e.rms_sigma, 1.6);
    EXPECT_NEAR(e.primitive.normal_force_N, press.object.normal_force_N, 0.1 * press.object.normal_force_N);
    if (c.shape == ContactShape::kSphere) {
      EXPECT_LT(std::hypot(e.primitive.x_mm - press.object.x_mm, e.primitive.y_mm - press.object.y_mm), 0.5);
    } else {
      EXPECT_EQ(e.primitive.length_mm, 0);  // across the pad, as the rod is
      EXPECT_NEAR(std::abs(std::sin(e.primitive.yaw_deg * 3.14159265358979 / 180)), 1.0, 0.02);
      EXPECT_NEAR(e.primitive.x_mm, press.object.x_mm, 0.5);
    }
  }
}

// A dead taxel whose misfit keeps the fit within max_rms_sigma but not adequate: off the
// contact (press_03, a 5 mm sphere at the centre, corner taxel 1 dead: 2.6 sigma over the
// hold, and a 2.6 mm punch won by absorbing it), under a punch's edge (press_22, a 6 x 6 mm
// punch, taxel 5 dead; press_29, a 5 x 2 mm punch, taxel 4) and under one sphere of a pair
// (press_24, taxel 7 under one sphere, 0 under the other). It reads nothing where the fit
// says it is loaded: left out, and the contact keeps its shape.
TEST(ContactReconstruction, ADeadTaxelTheFitStillExplainsWithinMaxRmsIsLeftOut) {
  struct Case {
    int press, taxel;
    ContactShape shape;
    bool pair;
    double force_N;
  };
  for (const Case& c : {Case{3, 1, ContactShape::kSphere, false, 0.8}, Case{22, 5, ContactShape::kPunch, false, 1.0},
                        Case{29, 4, ContactShape::kPunch, false, 0.5}, Case{24, 7, ContactShape::kSphere, true, 0.8},
                        Case{24, 0, ContactShape::kSphere, true, 0.8}}) {
    SCOPED_TRACE("press_" + std::to_string(c.press) + ", taxel " + std::to_string(c.taxel) + " dead");
    const sensors::CalibrationPress& press = Rig()[size_t(c.press)];
    ContactReconstructor r(Uskin());
    const ContactEstimate e = WithDeadTaxelAtHold(press, c.taxel, &r);
    ASSERT_TRUE(e.ok) << e.problem;
    ASSERT_EQ(e.taxel_use.size(), 16u);
    EXPECT_EQ(e.taxel_use[size_t(c.taxel)], TaxelUse::kLoneMisfit);
    EXPECT_EQ(e.primitive.shape, c.shape) << ContactShapeName(e.primitive.shape);
    EXPECT_EQ(e.two_contacts, c.pair);
    EXPECT_FALSE(e.model_inadequate) << e.rms_sigma;
    EXPECT_NEAR(e.normal_force_N(), c.force_N, 0.1 * c.force_N);
  }
}

// The same test on the healthy presses of a shape the fit first reads wrong (a sphere on a
// punch, inadequate while the punch is not yet tried: its centre taxel reads less than the
// dome predicts, by less than a dead one) leaves no taxel out: the presses' lone misfits
// are those of the test at max_rms_sigma alone (dead_reading_share 0).
TEST(ContactReconstruction, AWrongShapesMisfitLeavesNoTaxelOut) {
  for (int p : {21, 22, 23, 29}) {
    SCOPED_TRACE("press_" + std::to_string(p));
    const sensors::CalibrationPress& press = Rig()[size_t(p)];
    int64_t left_out[2] = {0, 0};
    for (int off = 0; off < 2; ++off) {
      ReconstructionOptions options;
      if (off) options.dead_reading_share = 0;
      ContactReconstructor r(Uskin(), options);
      for (const Eigen::VectorXd& readings : press.readings_N) r.Reconstruct(readings, std::vector<uint8_t>(16, 1));
      left_out[off] = r.counters().lone_taxels_left_out;
    }
    EXPECT_EQ(left_out[0], left_out[1]);
  }
}

}  // namespace
}  // namespace sedbridge::contact
