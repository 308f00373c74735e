// Contact in the warped PCG's preconditioner on a fingertip (B_coarse): the rest factor is
// taken without the contact springs even when the press starts in contact
// (fem::NewtonSystem), and the stiff-node update adds the springs of the nodes in contact
// (fem::StiffNodeUpdate). For the linear model that makes the preconditioner exact: one
// PCG iteration a step, where the rest factor alone needs several.

#include <gtest/gtest.h>

#include <cstdio>

#include "scene/fingertip_scene.h"

namespace sedbridge::scene {
namespace {

const model::FingertipModel& Model() {
  static const model::FingertipModel m = model::LoadFingertipModel("B_coarse");
  return m;
}

Eigen::VectorXd RestPositions() {
  const Eigen::Matrix3Xd& x = Model().soft.rest_positions_m;
  return Eigen::Map<const Eigen::VectorXd>(x.data(), x.size());
}

struct Press {
  Eigen::VectorXd x;
  int max_iterations_per_step = 0;
  int iterations = 0;
  bool matrix_free = false;  // the last step's
  int fallbacks = 0;
};

// A sphere pushed in and sideways fast (from touching), or the benchmark's plane press.
const char* kSphere = "{shape: sphere, radius_mm: 6, position_mm: [1, 0, 5.5], motion: {keyframes: [{t_s: 0, "
                      "offset_mm: [0, 0, 0]}, {t_s: 0.02, offset_mm: [0.5, 0, -1.0]}]}}";
const char* kPlane = "{shape: plane, rpy_deg: [180, 0, 0], position_mm: [0, 0, -0.5], motion: {keyframes: [{t_s: 0, "
                     "offset_mm: [0, 0, 0]}, {t_s: 1.0, offset_mm: [0, 0, -1.5]}]}}";

// single = false: the rest factor's solves in double (exactness checks; see
// solver.single_precision_factor).
// matrix_free = false: the element blocks assembled (solver.matrix_free).
Press RunPress(const std::string& elasticity, const std::string& solver, bool contact_update,
               const std::string& tolerance = "1.0e-10", const char* object = kSphere, bool single = false,
               int max_iterations = 500, bool matrix_free = true, bool fallback = false) {
  const std::string yaml = "model: B_coarse\nelasticity: " + elasticity + "\nsolver: {type: " + solver +
                           ", tolerance: " + tolerance + ", max_iterations: " + std::to_string(max_iterations) +
                           ", fallback_to_direct: " + (fallback ? "true" : "false") + ", contact_update: " + (contact_update ? "true" : "false") +
                           ", single_precision_factor: " + (single ? "true" : "false") +
                           ", matrix_free: " + (matrix_free ? "true" : "false") + "}\ndynamics: {integrator: backward_euler, dt_s: 0.001, newton_iterations: 1}\n"
                           "bone: {mode: fixed}\ncontact:\n  objects:\n    - " + object + "\n";
  FingertipScene s(ParseSceneDescription(yaml, "test"), Model());
  Press p;
  for (int k = 0; k < 20; ++k) {
    const fem::StepReport r = s.Step();
    if (max_iterations >= 500 || fallback) EXPECT_TRUE(r.converged) << solver << " step " << k;
    p.fallbacks += r.solver_fallbacks;
    p.max_iterations_per_step = std::max(p.max_iterations_per_step, r.linear_iterations);
    p.iterations += r.linear_iterations;
    if (k == 0) EXPECT_GT(s.contact()->active_contacts().size(), 0u) << "the press starts in contact";
  }
  EXPECT_GT(s.contact()->active_contacts().size(), 3u);
  p.x = s.simulation().positions_m();
  p.matrix_free = s.simulation().matrix_free();
  return p;
}

TEST(ContactPreconditioner, LinearPressTakesOnePcgIterationAStep) {
  const Press direct = RunPress("linear", "cholmod", true);
  const Press updated = RunPress("linear", "pcg_warp", true);
  const Press rest_only = RunPress("linear", "pcg_warp", false);
  EXPECT_EQ(updated.max_iterations_per_step, 1);
  EXPECT_GT(rest_only.max_iterations_per_step, 3);
  const Eigen::VectorXd rest = RestPositions();
  const Eigen::VectorXd u = direct.x - rest;
  ASSERT_GT(u.norm(), 0.0);
  EXPECT_LT((updated.x - direct.x).norm(), 1e-8 * u.norm());
  EXPECT_LT((rest_only.x - direct.x).norm(), 1e-8 * u.norm());
}

// Corotational: the warped factor is not exact (node rotations are averages of the
// elements'), but at the benchmark's tolerance the press needs far fewer iterations for the
// same trajectory.
TEST(ContactPreconditioner, CorotationalPressNeedsFewerIterations) {
  const Press direct = RunPress("corotational", "cholmod", true);
  const Press updated = RunPress("corotational", "pcg_warp", true, "1.0e-6");
  const Press rest_only = RunPress("corotational", "pcg_warp", false, "1.0e-6");
  const Press plane_updated = RunPress("corotational", "pcg_warp", true, "1.0e-6", kPlane);
  const Press plane_rest_only = RunPress("corotational", "pcg_warp", false, "1.0e-6", kPlane);
  std::printf("PCG iterations in 20 steps, plane: %d with the contact update, %d without\n", plane_updated.iterations,
              plane_rest_only.iterations);
  std::printf("PCG iterations in 20 steps, sphere: %d with the contact update, %d without\n", updated.iterations,
              rest_only.iterations);
  EXPECT_LT(4 * updated.iterations, 3 * rest_only.iterations);  // measured 154 vs 232
  EXPECT_LT(4 * plane_updated.iterations, 3 * plane_rest_only.iterations);  // measured 130 vs 275
  const Eigen::VectorXd rest = RestPositions();
  const double u = (direct.x - rest).norm();
  EXPECT_LT((updated.x - direct.x).norm(), 1e-5 * u);
  EXPECT_LT((rest_only.x - direct.x).norm(), 1e-5 * u);
}

// A step's first solve from the last two steps' velocity changes extrapolated
// (dynamics.extrapolate_warm_start, the default) instead of the last one's: the same press
// to the solver's tolerance, in fewer PCG iterations while the objects move steadily (the
// plane; a sphere pushed in and sideways over a second), and no more while the skin rings
// after kSphere's 20 ms push stops.
TEST(ContactPreconditioner, ExtrapolatedWarmStartSavesIterationsNotAccuracy) {
  const char* slow_sphere = "{shape: sphere, radius_mm: 6, position_mm: [1, 0, 5.7], motion: {keyframes: [{t_s: 0, "
                            "offset_mm: [0, 0, 0]}, {t_s: 1.0, offset_mm: [1.5, 0, -1.5]}]}}";
  for (const char* object : {kPlane, slow_sphere, kSphere}) {
    Eigen::VectorXd x[2];
    int iterations[2] = {0, 0};
    for (int extrapolate = 0; extrapolate < 2; ++extrapolate) {
      const std::string yaml = std::string("model: B_coarse\nelasticity: corotational\n") +
                               "solver: {type: pcg_warp, tolerance: 1.0e-6, max_iterations: 500, fallback_to_direct: false}\n"
                               "dynamics: {integrator: backward_euler, dt_s: 0.001, newton_iterations: 1, "
                               "extrapolate_warm_start: " + (extrapolate ? "true" : "false") + "}\n"
                               "bone: {mode: fixed}\ncontact:\n  objects:\n    - " + object + "\n";
      FingertipScene s(ParseSceneDescription(yaml, "test"), Model());
      for (int k = 0; k < 100; ++k) {
        const fem::StepReport r = s.Step();
        ASSERT_TRUE(r.converged) << k;
        if (k >= 50) iterations[extrapolate] += r.linear_iterations;  // past the first touch's ringing
      }
      EXPECT_GT(s.contact()->active_contacts().size(), 0u);
      x[extrapolate] = s.simulation().positions_m();
    }
    std::printf("PCG iterations in steps 50-99: %d extrapolated, %d from the last step\n", iterations[1], iterations[0]);
    const double u = (x[0] - RestPositions()).norm();
    EXPECT_LT((x[1] - x[0]).norm(), 1e-5 * u);
    if (object == kSphere)
      EXPECT_LT(iterations[1], 1.05 * iterations[0]);
    else
      EXPECT_LT(iterations[1], 0.85 * iterations[0]);
  }
}

// The default single-precision copy of the rest factor: the same PCG iterations within a
// few (it is exact to ~1e-7, not to round-off) and the same trajectory to the tolerance.
TEST(ContactPreconditioner, SinglePrecisionFactorKeepsIterationsAndAnswer) {
  for (const char* object : {kSphere, kPlane}) {
    const Press dbl = RunPress("corotational", "pcg_warp", true, "1.0e-6", object, false);
    const Press single = RunPress("corotational", "pcg_warp", true, "1.0e-6", object, true);
    std::printf("PCG iterations in 20 steps: %d single, %d double\n", single.iterations, dbl.iterations);
    EXPECT_LE(single.iterations, dbl.iterations + 5);
    const double u = (dbl.x - RestPositions()).norm();
    ASSERT_GT(u, 0.0);
    EXPECT_LT((single.x - dbl.x).norm(), 1e-5 * u);
  }
  // The linear press, whose double factor is exact (one iteration): two at most.
  const Press linear = RunPress("linear", "pcg_warp", true, "1.0e-6", kSphere, true);
  EXPECT_LE(linear.max_iterations_per_step, 2);
}

// A PCG without direct fallback takes its products from the element kernel and leaves the
// element blocks out of the matrix (fem/step_operator.h); its preconditioner's contact
// update reads the diagonal blocks through the same operator. Corotational presses, to
// tolerance and capped at one iteration a step (the real-time setting): the same trajectory
// as with the blocks assembled, to round-off, and the same PCG iterations. (Rest factor in
// double: a capped iterate is its preconditioned residual, which the float factor gives to
// ~1e-7 only, so round-off in its input moves it by that much.)
TEST(ContactPreconditioner, MatrixFreeStepsGiveTheAssembledSteps) {
  for (const char* object : {kSphere, kPlane})
    for (int cap : {500, 1}) {
      const Press free = RunPress("corotational", "pcg_warp", true, "1.0e-8", object, false, cap, true);
      const Press assembled = RunPress("corotational", "pcg_warp", true, "1.0e-8", object, false, cap, false);
      EXPECT_TRUE(free.matrix_free);
      EXPECT_FALSE(assembled.matrix_free);
      EXPECT_EQ(free.iterations, assembled.iterations) << "cap " << cap;
      const double u = (assembled.x - RestPositions()).norm();
      ASSERT_GT(u, 0.0);
      std::printf("matrix-free against assembled, cap %d: %d / %d PCG iterations, positions %.1e apart (relative)\n",
                  cap, free.iterations, assembled.iterations, (free.x - assembled.x).norm() / u);
      EXPECT_LT((free.x - assembled.x).norm(), 1e-12 * u) << "cap " << cap;  // measured 2.5e-15 to 2.1e-14
    }
  // A direct solver needs the matrix whole.
  EXPECT_FALSE(RunPress("corotational", "cholmod", true).matrix_free);
}

// A matrix-free PCG that cannot converge (capped at 2 iterations to 1e-10) falls back to
// the direct solver, which needs every block: the operator assembles the ones it left out
// at the step's state first. Nearly every step falls back, so the press is the direct solver's.
TEST(ContactPreconditioner, AMatrixFreeStepThatFallsBackAssemblesTheMatrixFirst) {
  const Press direct = RunPress("corotational", "cholmod", true);
  const Press free = RunPress("corotational", "pcg_warp", true, "1.0e-10", kSphere, false, 2, true, true);
  EXPECT_GE(free.fallbacks, 15);  // measured 19 of 20
  const double u = (direct.x - RestPositions()).norm();
  ASSERT_GT(u, 0.0);
  EXPECT_LT((free.x - direct.x).norm(), 1e-10 * u);
}

}  // namespace
}  // namespace sedbridge::scene
