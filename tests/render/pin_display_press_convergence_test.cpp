// A pin display's full-contact press where the contact solve's accelerated iterations cycle:
// pin_8x8 (1 mm pitch, pressed as pins of the skin's sample spacing, so neighbours overlap)
// with most of its pins raised up to its travel on B_coarse. Before the solve's unaccelerated
// fallback (fem::ComplianceContactOptions::monotone_fallback) this press failed 41 % of the
// way ("not converged in 200 iterations", at every retried step down to 1/32). The answer
// must meet the penalty law as a fixed point, checked here from the solve's public output
// alone: the reported contact forces (k * depth at the final positions, >= 0) applied
// through the compliance W give back those positions.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "display/display_profile.h"
#include "model/fingertip_model.h"
#include "render/display_on_leader.h"
#include "render/pin_display_on_leader.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::render {
namespace {

// 58 of 64 pins raised, up to the 2 mm travel [mm] (drawn at random once; row by row).
const std::vector<double> kHeights_mm{
    1.780, 0.000, 1.528, 0.864, 0.658, 0.252, 0.000, 0.902, 1.674, 1.616, 1.594, 0.018, 1.986,
    1.850, 0.486, 0.422, 1.100, 0.954, 0.438, 0.988, 0.624, 0.560, 0.230, 1.858, 1.864, 1.636,
    1.926, 1.254, 0.584, 1.670, 0.000, 0.746, 0.482, 1.990, 1.518, 0.722, 0.000, 1.596, 1.450,
    1.060, 0.932, 0.180, 1.058, 0.180, 0.652, 1.418, 0.648, 1.456, 0.570, 0.000, 0.424, 1.642,
    0.874, 0.506, 0.694, 1.046, 1.672, 1.894, 0.776, 1.078, 1.926, 0.932, 0.000, 1.112};

TEST(PinDisplayPress, ManyRaisedPinsAtOneMillimetrePitchConvergeToThePenaltyLaw) {
  const model::FingertipModel model = model::LoadFingertipModel("B_coarse");
  scene::FingertipCompliance leader(model, DisplayLeaderOptions());
  const display::DisplayProfile profile = display::LoadNamedDisplayProfile("pin_8x8");
  PinDisplayOnLeader display(leader, profile.device);
  ASSERT_EQ(display.num_actuators(), int(kHeights_mm.size()));
  const Eigen::VectorXd heights = Eigen::Map<const Eigen::VectorXd>(kHeights_mm.data(), Eigen::Index(kHeights_mm.size()));
  ASSERT_LE(heights.maxCoeff(), profile.device.travel_mm);
  // Neighbouring pins overlap as pressed: the hard case.
  EXPECT_GT(2 * display.pressed_radius_mm(), 1.0);

  const fem::ComplianceQpCounts before = leader.contact().qp_counts();
  Eigen::VectorXd sed;
  ASSERT_TRUE(display.Press(heights, sed)) << display.error();
  const fem::ComplianceStepResult& r = leader.contact().last();
  ASSERT_TRUE(r.ok);
  EXPECT_TRUE(r.converged);
  ASSERT_EQ(sed.size(), Eigen::Index(leader.contact().sed_vertices().size()));
  EXPECT_TRUE(sed.allFinite());
  EXPECT_GE(sed.minCoeff(), 0.0);
  std::printf("press: %zu contacts, peak SED %.1f Pa, %d iterations in the last step; steps that fell back %llu\n",
              r.contacts.size(), sed.maxCoeff(), r.iterations,
              static_cast<unsigned long long>(leader.contact().qp_counts().monotone_fallbacks - before.monotone_fallbacks));

  // The reported forces: non-negative and k * depth (the penalty law at the final positions).
  const fem::ComplianceContact& contact = leader.contact();
  const double k = contact.options().stiffness_N_m;
  const int samples = contact.num_samples();
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * samples);
  double largest_N = 0, deepest_m = 0;
  int on_pins = 0;
  for (const fem::ActiveContact& c : r.contacts) {
    ASSERT_GE(c.sample, 0);
    ASSERT_LT(c.sample, samples);
    EXPECT_GE(c.normal_force_N, 0.0);
    EXPECT_NEAR(c.normal_force_N, k * c.depth_m, 1e-12 * (1 + c.normal_force_N));
    f.segment<3>(3 * c.sample) += c.normal_force_N * c.normal;
    largest_N = std::max(largest_N, c.normal_force_N);
    deepest_m = std::max(deepest_m, c.depth_m);
    on_pins += c.object > 0;  // object 0 is the plate
  }
  EXPECT_GT(on_pins, 20);
  EXPECT_LE(deepest_m, largest_N / k * (1 + 1e-12));
  std::printf("largest contact force %.4f N, deepest penetration %.2f um (penalty k %.0f N/m)\n", largest_N, 1e6 * deepest_m, k);

  // The fixed point: those forces through W give the positions they were read at (the
  // candidates' displacements; the solve's law tolerance is 1e-8 of the largest force).
  const Eigen::VectorXd u = contact.compliance_m_N() * f;
  const Eigen::Map<const Eigen::Matrix3Xd> u_c = contact.candidate_displacements_m();
  const Eigen::Index candidates = u_c.cols();
  const Eigen::VectorXd u_reported = Eigen::Map<const Eigen::VectorXd>(u_c.data(), 3 * candidates);
  const double error = (u.head(3 * candidates) - u_reported).norm() / u_reported.norm();
  std::printf("W f against the positions: rel %.2e\n", error);
  EXPECT_LT(error, 1e-6);
}

}  // namespace
}  // namespace sedbridge::render
