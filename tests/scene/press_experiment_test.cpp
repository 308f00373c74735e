#include "scene/press_experiment.h"

#include <gtest/gtest.h>
#include <omp.h>
#include "tests/common/scratch_dir.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/resource_path.h"
#include "fem/thread_team.h"

namespace sedbridge::scene {
namespace {

TEST(PressExperiment, CoarsePressWritesTheOutputContract) {
  SceneDescription d = ReadSceneDescription(config::ResolveResource("config/scenes/paper_press.yaml"));
  d.model = "B_coarse";
  d.steps = 10;
  d.dt_s = 0.1;
  d.outputs.vtu_every = 5;
  FingertipScene scene(d);
  const std::string dir = sedbridge::testing::ScratchDir() + "/press_contract";
  PressOptions options;
  options.vtu_dir = dir;
  const PressResult r = RunPress(scene, options);
  WritePressCsv(scene, r, dir);
  ASSERT_EQ(r.steps.size(), 10u);
  for (size_t i = 1; i < r.steps.size(); ++i) {
    EXPECT_GT(r.steps[i].force_N, r.steps[i - 1].force_N) << "force must grow with depth";
    EXPECT_GE(r.steps[i].contact_area_mm2, r.steps[i - 1].contact_area_mm2);
    EXPECT_TRUE(r.steps[i].report.converged) << "step " << i;
  }
  EXPECT_NEAR(r.steps.back().displacement_mm, 2.0, 1e-9);
  EXPECT_GT(r.steps.back().force_N, 0.3);  // paper Fig. 6: O(1 N) at 2 mm
  EXPECT_LT(r.steps.back().force_N, 10.0);
  EXPECT_GT(r.selected_max_sed_Pa, 0.0);
  EXPECT_FALSE(r.path.empty());
  for (const char* f : {"force_displacement.csv", "merkel_sed.csv", "sed_path.csv", "frames.pvd", "frame_0005.vtu",
                        "frame_0010.vtu"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + f)) << f;
  std::ifstream fd(dir + "/force_displacement.csv");
  std::string header;
  std::getline(fd, header);
  EXPECT_EQ(header, "step,displacement_mm,force_N,contact_area_mm2");
  std::ifstream path(dir + "/sed_path.csv");
  std::getline(path, header);
  EXPECT_EQ(header, "x_mm,sed_Pa,sed_normalized");
  // step_timing.csv: one row per step, each with the OpenMP team it ran on: the caller's
  // when OMP_NUM_THREADS is set (ctest sets 1), else the step's own choice.
  std::ifstream timing(dir + "/step_timing.csv");
  std::getline(timing, header);
  EXPECT_EQ(header, "step,wall_ms,newton_iterations,linear_iterations,solver_fallbacks,converged,inverted_elements,threads");
  int rows = 0;
  for (std::string line; std::getline(timing, line); ++rows) {
    const int threads = std::stoi(line.substr(line.rfind(',') + 1));
    EXPECT_EQ(threads, r.steps[size_t(rows)].report.threads) << line;
    if (fem::AutoThreadTeam()) {
      EXPECT_GE(threads, 1) << line;
      EXPECT_LE(threads, omp_get_num_procs()) << line;
    } else {
      EXPECT_EQ(threads, omp_get_max_threads()) << line;
    }
  }
  EXPECT_EQ(rows, 10);
}

// The shipped paper's press solves Newton's linear systems by PCG with the warped rest
// factor: the same equilibria as refactorizing every iteration, in the same Newton
// iterations (the outputs of the press on B are byte-identical, docs/performance.md).
TEST(PressExperiment, PcgWarpReachesTheDirectSolversEquilibria) {
  SceneDescription d = ReadSceneDescription(config::ResolveResource("config/scenes/paper_press.yaml"));
  EXPECT_EQ(d.solver, SolverKind::kPcgWarp);
  d.model = "B_coarse";
  d.steps = 10;
  d.dt_s = 0.1;
  d.outputs.vtu_every = 0;
  auto run = [&](SolverKind solver) {
    SceneDescription e = d;
    e.solver = solver;
    FingertipScene scene(e);
    return RunPress(scene, PressOptions{});
  };
  const PressResult pcg = run(SolverKind::kPcgWarp), direct = run(SolverKind::kCholmod);
  ASSERT_EQ(pcg.steps.size(), direct.steps.size());
  int pcg_newton = 0, direct_newton = 0;
  for (size_t i = 0; i < pcg.steps.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_TRUE(pcg.steps[i].report.converged);
    EXPECT_EQ(pcg.steps[i].report.solver_fallbacks, 0);
    EXPECT_NEAR(pcg.steps[i].force_N, direct.steps[i].force_N, 1e-6 * direct.steps[i].force_N + 1e-12);
    EXPECT_LE((pcg.merkel_sed[i] - direct.merkel_sed[i]).norm(), 1e-5 * direct.merkel_sed[i].norm() + 1e-9);
    pcg_newton += pcg.steps[i].report.newton_iterations;
    direct_newton += direct.steps[i].report.newton_iterations;
  }
  EXPECT_LE(std::abs(pcg_newton - direct_newton), 2) << pcg_newton << " vs " << direct_newton;
  EXPECT_GT(pcg.steps.back().report.linear_iterations, 0);  // it did iterate
}

// The accurate preset solves its Newton iterations by warped PCG to 1e-6: a backward Euler
// press (3 Newton iterations a step) gives refactorizing CHOLMOD's answer.
TEST(PressExperiment, AccuratePresetGivesTheRefactorizingAnswer) {
  SceneDescription d = ReadSceneDescription(config::ResolveResource("config/scenes/paper_press.yaml"));
  d.model = "B_coarse";
  d.steps = 10;
  d.dt_s = 0.01;
  d.integrator.kind = fem::IntegratorKind::kBackwardEuler;
  d.outputs.vtu_every = 0;
  ApplyPreset("accurate", d);
  EXPECT_EQ(d.solver, SolverKind::kPcgWarp);
  EXPECT_EQ(d.integrator.newton_iterations, 3);
  SceneDescription refactorizing = d;
  refactorizing.solver = SolverKind::kCholmod;
  FingertipScene a(d), b(refactorizing);
  const PressResult pcg = RunPress(a, PressOptions{}), direct = RunPress(b, PressOptions{});
  ASSERT_EQ(pcg.steps.size(), direct.steps.size());
  for (size_t i = 0; i < pcg.steps.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(pcg.steps[i].report.solver_fallbacks, 0);
    EXPECT_NEAR(pcg.steps[i].force_N, direct.steps[i].force_N, 1e-5 * direct.steps[i].force_N + 1e-9);
    EXPECT_LE((pcg.merkel_sed[i] - direct.merkel_sed[i]).norm(), 1e-5 * direct.merkel_sed[i].norm() + 1e-9);
  }
  EXPECT_GT(direct.steps.back().force_N, 0.05);  // it pressed
}

TEST(PressExperiment, NoFiniteForceIsAClearErrorNotACrash) {
  // A hostile input: contact.stiffness_N_m: 1e300 gave non-finite forces at every step, no step was
  // selected and index -1 was read (SIGSEGV).
  SceneDescription d = ReadSceneDescription(config::ResolveResource("config/scenes/paper_press.yaml"));
  d.model = "B_coarse";
  d.steps = 2;
  d.dt_s = 0.5;
  d.outputs.vtu_every = 0;
  ASSERT_TRUE(d.contact.has_value());
  d.contact->params.stiffness_N_m = 1e300;
  FingertipScene scene(d);
  try {
    const PressResult r = RunPress(scene, PressOptions{});
    // If the solver happens to stay finite, a step must have been selected.
    EXPECT_GE(r.selected, 0);
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no step has a finite contact force"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sedbridge::scene
