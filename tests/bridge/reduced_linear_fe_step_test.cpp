// The reduced linear FE step gives the scene-based step's Merkel SED (same linear model),
// and refuses scenes where the map is not linear.

#include "bridge/reduced_linear_fe_step.h"

#include <gtest/gtest.h>

#include <random>

#include "bridge_test_util.h"

namespace sedbridge::bridge {
namespace {

TEST(ReducedLinearFeStep, MatchesTheSceneStepForRandomLoads) {
  const sensors::SensorProfile p = sensors::LoadNamedSensorProfile("uskin_4x4");
  const PadRegistration reg(p.taxels);
  const scene::SceneDescription d = BridgeSceneDescription("B_coarse", "fast");
  SceneFeStep full(d, p, reg);
  ReducedLinearFeStep reduced(d, p, reg);
  EXPECT_EQ(reduced.displacement_map().cols(), 48);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> pressure(0, 15e3), shear(-2e3, 2e3);
  for (int trial = 0; trial < 4; ++trial) {
    TaxelValues v;
    for (int i = 0; i < 16; ++i) {
      v.pressure_Pa.push_back(pressure(rng));
      v.shear_x_Pa.push_back(trial == 0 ? 0.0 : shear(rng));
      v.shear_y_Pa.push_back(trial == 0 ? 0.0 : shear(rng));
    }
    const MerkelSedResult& a = full.Step(v);
    ASSERT_TRUE(a.ok) << a.error;
    const Eigen::VectorXd sed_full = *a.sed_Pa;
    const double force_full = a.applied_force_N;
    const MerkelSedResult& b = reduced.Step(v);
    ASSERT_TRUE(b.ok) << b.error;
    EXPECT_LT((*b.sed_Pa - sed_full).norm(), 1e-6 * sed_full.norm()) << "trial " << trial;
    EXPECT_NEAR(b.applied_force_N, force_full, 1e-9 * force_full);
  }
}

TEST(ReducedLinearFeStep, RefusesNonlinearScenes) {
  const sensors::SensorProfile p = sensors::LoadNamedSensorProfile("uskin_4x4");
  EXPECT_THROW(ReducedLinearFeStep(BridgeSceneDescription("B_coarse", "accurate"), p, PadRegistration(p.taxels)),
               std::invalid_argument);
}

TEST(ReducedLinearFeStep, NonFiniteValuesNeverEvaluated) {
  const sensors::SensorProfile p = sensors::LoadNamedSensorProfile("uskin_4x4");
  ReducedLinearFeStep reduced(BridgeSceneDescription("B_coarse", "fast"), p, PadRegistration(p.taxels));
  TaxelValues v;
  v.pressure_Pa.assign(16, 1000.0);
  v.pressure_Pa[3] = std::nan("");
  EXPECT_FALSE(reduced.Step(v).ok);
}

// Two fingers on one precompute (a hand, bridge/leader_model_cache.h): each step's SED is
// bit for bit what a step of its own gives, whatever the other finger stepped in between
// (each evaluates its own copy of the Merkel layer).
TEST(ReducedLinearFeStep, StepsSharingOnePrecomputeGiveWhatStepsOfTheirOwnGive) {
  const sensors::SensorProfile p = sensors::LoadNamedSensorProfile("uskin_4x4");
  const scene::SceneDescription d = BridgeSceneDescription("B_coarse", "fast");
  ReducedLinearFeStep first(d, p, PadRegistration(p.taxels));
  ReducedLinearFeStep second(first.precompute());
  ReducedLinearFeStep own_first(d, p, PadRegistration(p.taxels)), own_second(d, p, PadRegistration(p.taxels));
  EXPECT_EQ(second.precompute().get(), first.precompute().get());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pressure(0, 15e3);
  for (int trial = 0; trial < 4; ++trial) {
    TaxelValues a, b;
    for (int i = 0; i < 16; ++i) {
      a.pressure_Pa.push_back(pressure(rng));
      b.pressure_Pa.push_back(trial % 2 ? 0.0 : pressure(rng));
    }
    const Eigen::VectorXd sed_first = *first.Step(a).sed_Pa;
    const Eigen::VectorXd sed_second = *second.Step(b).sed_Pa;
    EXPECT_EQ(sed_first, *own_first.Step(a).sed_Pa) << "trial " << trial;
    EXPECT_EQ(sed_second, *own_second.Step(b).sed_Pa) << "trial " << trial;
  }
  EXPECT_THROW(ReducedLinearFeStep(nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::bridge
