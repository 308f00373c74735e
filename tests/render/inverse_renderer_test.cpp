#include "render/inverse_renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "display/safety_limiter.h"
#include "render_test_util.h"

namespace sedbridge::render {
namespace {

constexpr int kActuators = 8;
constexpr double kMax = 20.0;

InverseRenderer MakeRenderer(double preload = 1e-3, double max = kMax) {
  return InverseRenderer(DisplayInfluence(testing::SyntheticInfluence(kActuators, 60, preload)),
                         Eigen::VectorXd::Constant(kActuators, max));
}

// The SED a command vector adds to the preloaded pad: what the renderer aims at.
Eigen::VectorXd AddedSed(const InverseRenderer& r, const Eigen::VectorXd& u) {
  Eigen::VectorXd sed;
  r.influence().Sed(u, sed);
  return sed - r.influence().preload_sed_Pa();
}

TEST(InverseRenderer, ARenderableTargetIsRecoveredToTheSolversTolerance) {
  InverseRenderer renderer = MakeRenderer();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> level(0.2 * kMax, 0.8 * kMax);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd truth(kActuators);
    for (int a = 0; a < kActuators; ++a) truth[a] = level(rng);
    const Eigen::VectorXd target = AddedSed(renderer, truth);
    renderer.Reset();
    const Eigen::VectorXd& u = renderer.Render(target);
    EXPECT_TRUE(renderer.last().converged) << trial;
    // The solver stops when no command moves by 1e-4 of its maximum (command_tolerance).
    EXPECT_LE((u - truth).lpNorm<Eigen::Infinity>(), 1e-3 * kMax) << trial;
    EXPECT_LE((AddedSed(renderer, u) - target).norm(), 1e-3 * target.norm()) << trial;
  }
}

TEST(InverseRenderer, AnUnreachablePointGetsTheBoundedBest) {
  InverseRenderer renderer = MakeRenderer();
  // A 0.5 mm point: one vertex at 100 kPa, nothing around it (no command vector makes it).
  Eigen::VectorXd target = Eigen::VectorXd::Zero(renderer.influence().num_vertices());
  target[29] = 1e5;
  const Eigen::VectorXd u = renderer.Render(target);
  EXPECT_GE(u.minCoeff(), 0.0);
  EXPECT_LE(u.maxCoeff(), kMax);
  EXPECT_GT(renderer.last().at_upper_bound, 0);  // pushed as far as it may go under the point
  // Bounded best: no feasible move along any single coordinate lowers the cost.
  auto cost = [&](const Eigen::VectorXd& v) {
    const Eigen::VectorXd root = (AddedSed(renderer, v) + renderer.influence().preload_sed_Pa()).array().max(0.0).matrix();
    const Eigen::VectorXd want = (target + renderer.influence().preload_sed_Pa());
    return 0.5 * ((root.array() + 10.0).sqrt() - (want.array() + 10.0).sqrt()).matrix().squaredNorm();
  };
  const double best = cost(u);
  for (int a = 0; a < kActuators; ++a)
    for (double move : {-0.05 * kMax, 0.05 * kMax}) {
      Eigen::VectorXd v = u;
      v[a] = std::clamp(v[a] + move, 0.0, kMax);
      EXPECT_GE(cost(v), best * (1 - 1e-9)) << a << " " << move;
    }
}

TEST(InverseRenderer, ZeroTargetGivesZeroCommandsFromAnyWarmStart) {
  InverseRenderer renderer = MakeRenderer();
  renderer.Render(AddedSed(renderer, Eigen::VectorXd::Constant(kActuators, 10.0)));
  ASSERT_GT(renderer.commands().maxCoeff(), 1.0);
  const Eigen::VectorXd u = renderer.Render(Eigen::VectorXd::Zero(renderer.influence().num_vertices()));
  EXPECT_EQ(u.lpNorm<Eigen::Infinity>(), 0.0);
  EXPECT_FALSE(renderer.last().fault);
}

TEST(InverseRenderer, NonFiniteTargetGivesZerosAndTheFaultFlag) {
  InverseRenderer renderer = MakeRenderer();
  renderer.Render(AddedSed(renderer, Eigen::VectorXd::Constant(kActuators, 10.0)));
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity()}) {
    Eigen::VectorXd target = AddedSed(renderer, Eigen::VectorXd::Constant(kActuators, 10.0));
    target[5] = bad;
    const Eigen::VectorXd u = renderer.Render(target);
    EXPECT_TRUE(renderer.last().fault);
    EXPECT_EQ(u.lpNorm<Eigen::Infinity>(), 0.0);
  }
  // A wrong size is no field either.
  EXPECT_EQ(renderer.Render(Eigen::VectorXd::Ones(3)).lpNorm<Eigen::Infinity>(), 0.0);
  EXPECT_TRUE(renderer.last().fault);
}

TEST(InverseRenderer, WithTheLimiterAfterItCommandsNeverExceedMaxNorSlewHoweverTheTargetJumps) {
  InverseRenderer renderer = MakeRenderer(1e-3, 40.0);  // the renderer may ask for more than the limiter allows
  display::SafetyLimits limits;
  limits.max.assign(kActuators, kMax);
  limits.slew_rate_per_s = 200.0;
  limits.watchdog_timeout_s = 0.1;
  display::SafetyLimiter limiter(limits);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> scale(0.0, 1.0);
  std::vector<double> previous(kActuators, 0.0);
  const std::int64_t dt_us = 10000;  // 100 Hz scans
  int at_ceiling = 0;
  for (int k = 0; k < 400; ++k) {
    Eigen::VectorXd target;
    const int kind = int(scale(rng) * 4);
    if (kind == 0) target = Eigen::VectorXd::Zero(renderer.influence().num_vertices());
    if (kind == 1) target = AddedSed(renderer, Eigen::VectorXd::Constant(kActuators, 40.0 * scale(rng)));
    if (kind == 2) target = Eigen::VectorXd::Constant(renderer.influence().num_vertices(), 1e7 * scale(rng));
    if (kind == 3) {
      target = AddedSed(renderer, Eigen::VectorXd::Constant(kActuators, 5.0));
      target[size_t(k) % target.size()] = scale(rng) < 0.5 ? std::nan("") : 1e9;
    }
    const Eigen::VectorXd& u = renderer.Render(target);
    ASSERT_GE(u.minCoeff(), 0.0);
    ASSERT_LE(u.maxCoeff(), 40.0);
    const std::vector<double> request(u.data(), u.data() + u.size());
    const std::int64_t now = std::int64_t(k + 1) * dt_us;
    const display::LimitedOutput& out = limiter.Apply(now, now, request);
    for (int a = 0; a < kActuators; ++a) {
      ASSERT_GE(out.value[size_t(a)], 0.0);
      ASSERT_LE(out.value[size_t(a)], kMax);
      ASSERT_LE(out.value[size_t(a)] - previous[size_t(a)], 200.0 * 0.01 + 1e-9) << k;
      at_ceiling += out.value[size_t(a)] == kMax;
    }
    previous = out.value;
  }
  EXPECT_GT(at_ceiling, 0);  // the bound was reached, so the check above could have failed
}

TEST(InverseRenderer, AnEvaluationBudgetBoundsEachScanAndLaterScansReachTheSameAnswer) {
  InverseRendererOptions budgeted;
  budgeted.max_iterations = 8;
  budgeted.max_evaluations = 2;
  const DisplayInfluence influence(testing::SyntheticInfluence(kActuators, 60, 1e-3));
  InverseRenderer bounded(influence, Eigen::VectorXd::Constant(kActuators, kMax), budgeted);
  InverseRenderer free_running(influence, Eigen::VectorXd::Constant(kActuators, kMax));
  Eigen::VectorXd truth(kActuators);
  for (int a = 0; a < kActuators; ++a) truth[a] = kMax * (0.2 + 0.08 * a);
  const Eigen::VectorXd target = AddedSed(free_running, truth);
  const Eigen::VectorXd unbounded = free_running.Render(target);
  ASSERT_TRUE(free_running.last().converged);
  ASSERT_GT(free_running.last().evaluations, 2);  // so the budget below is binding
  // The same target scan after scan: each render spends at most two evaluations, stays in
  // the box, and goes on from where the last stopped until it converges where an unbounded
  // render does.
  bool stopped_by_budget = false, converged = false;
  for (int scan = 0; scan < 40 && !converged; ++scan) {
    const Eigen::VectorXd& u = bounded.Render(target);
    ASSERT_LE(bounded.last().evaluations, 2) << scan;
    ASSERT_GE(u.minCoeff(), 0.0);
    ASSERT_LE(u.maxCoeff(), kMax);
    stopped_by_budget |= bounded.last().out_of_evaluations;
    EXPECT_FALSE(bounded.last().out_of_evaluations && bounded.last().converged) << scan;
    converged = bounded.last().converged;
  }
  EXPECT_TRUE(stopped_by_budget);
  ASSERT_TRUE(converged);
  EXPECT_LE((bounded.commands() - unbounded).lpNorm<Eigen::Infinity>(), 1e-3 * kMax);
  EXPECT_THROW(InverseRenderer(influence, Eigen::VectorXd::Constant(kActuators, kMax),
                               InverseRendererOptions{10.0, 8, -1}),
               std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::render
