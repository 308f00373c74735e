// Contact reconstruction (contact/contact_reconstruction.h) and the sensor forward model it
// inverts (sensors/tactile_forward_model.h): what each contact model costs.
// Run (Release build):
//   build/tests/bench/reconstruction_benchmark
//   build/tests/bench/reconstruction_benchmark --benchmark_filter=ReconstructPress
// ForwardModel/<shape>: one PredictLinearInShear (the unit every fit is counted in), with
//   the patch's cells as a counter.
// ReconstructPress/<press>/<models>/<force_step>: every scan of a calibration-rig press
//   through a fresh reconstructor, as the bridge runs it; models: 0 = crossing rods, spheres
//   and flats only, 1 = + finite rods (fe.finite_rods), 2 = + pairs (fe.two_contacts), 3 =
//   both (the default); force_step: ReconstructionOptions::force_step_first (1, the
//   default). ReconstructPressExplainedBudget/<press>/<budget>: the candidate's budget on
//   scans the current model explains (6, the default, or 0 = the full 12).
//   ReconstructPressJacobian/<press>/<refresh>: ReconstructionOptions::jacobian_refresh (1 =
//   finite differences every LM iteration, 4 = the default's Broyden updates). Counters: per-scan median / p99 / max ms (wall clock, over the press's scans),
//   evaluations per scan (deterministic: the cost without the machine's noise) with their p99
//   and max over the press's scans (p99_evals, max_evals: the worst scans' work), fallbacks.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "contact/contact_reconstruction.h"
#include "common/resource_path.h"
#include "sensors/calibration_press.h"
#include "tests/bench/rig_presses.h"

namespace sedbridge {
namespace {

using bench::Profile;
using bench::Rig;

sensors::ContactPrimitive Shape(int which) {
  sensors::ContactPrimitive c;
  c.x_mm = 1.0, c.y_mm = -0.5, c.normal_force_N = 0.8, c.shear_x_N = 0.05;
  switch (which) {
    case 0: c.radius_mm = 5; break;  // sphere
    case 1: c.shape = sensors::ContactShape::kCylinder, c.radius_mm = 1.5, c.yaw_deg = 30; break;
    case 2: c.shape = sensors::ContactShape::kCylinder, c.radius_mm = 1.5, c.yaw_deg = 30, c.length_mm = 8; break;
    default: c.shape = sensors::ContactShape::kFlat; break;
  }
  return c;
}

void ForwardModel(benchmark::State& state) {
  const sensors::TactileForwardModel model(Profile(), Profile().forward_model);
  const sensors::ContactPrimitive c = Shape(static_cast<int>(state.range(0)));
  Eigen::VectorXd normal, per_x, per_y;
  int cells = 0;
  for (auto _ : state) {
    model.PredictLinearInShear(c, &normal, &per_x, &per_y, &cells);
    benchmark::DoNotOptimize(normal.data());
  }
  state.counters["cells"] = cells;
}
BENCHMARK(ForwardModel)->ArgName("sphere_rod_finite_flat")->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);

// Every scan of `press` through a fresh reconstructor with `options`; per-scan counters.
void RunPress(benchmark::State& state, const sensors::CalibrationPress& press, const contact::ReconstructionOptions& options) {
  std::vector<double> ms;
  std::vector<int> scan_evaluations;
  int64_t evaluations = 0, fallbacks = 0, scans = 0;
  for (auto _ : state) {
    contact::ContactReconstructor r(Profile(), options);
    scan_evaluations.clear();
    for (const auto& scan : press.scans) {
      const auto t0 = std::chrono::steady_clock::now();
      const contact::ContactEstimate& e = r.Reconstruct(scan);
      benchmark::DoNotOptimize(e.primitive.normal_force_N);
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      scan_evaluations.push_back(e.evaluations);
    }
    evaluations += r.counters().evaluations;
    fallbacks += r.counters().fallbacks;
    scans += r.counters().scans;
  }
  std::sort(ms.begin(), ms.end());
  state.SetLabel(press.name);
  state.counters["median_ms"] = ms[ms.size() / 2];
  state.counters["p99_ms"] = ms[ms.size() * 99 / 100];
  state.counters["max_ms"] = ms.back();
  state.counters["evals_per_scan"] = double(evaluations) / double(scans);
  std::sort(scan_evaluations.begin(), scan_evaluations.end());
  state.counters["p99_evals"] = scan_evaluations[scan_evaluations.size() * 99 / 100];
  state.counters["max_evals"] = scan_evaluations.back();
  state.counters["fallbacks"] = double(fallbacks) / double(state.iterations());
}

void ReconstructPress(benchmark::State& state) {
  contact::ReconstructionOptions options;
  options.fit_finite_rods = (state.range(1) & 1) != 0;
  options.fit_pairs = (state.range(1) & 2) != 0;
  options.force_step_first = state.range(2) != 0;
  RunPress(state, Rig()[static_cast<size_t>(state.range(0))], options);
}

// The candidate budget while the current model explains the scan
// (ReconstructionOptions::explained_candidate_evaluations; 0 = the full candidate budget).
void ReconstructPressExplainedBudget(benchmark::State& state) {
  contact::ReconstructionOptions options;
  options.explained_candidate_evaluations = static_cast<int>(state.range(1));
  RunPress(state, Rig()[static_cast<size_t>(state.range(0))], options);
}
// Finite-difference Jacobians every LM iteration (jacobian_refresh 1) or Broyden updates of
// the pose columns between them (4, the default).
void ReconstructPressJacobian(benchmark::State& state) {
  contact::ReconstructionOptions options;
  options.jacobian_refresh = static_cast<int>(state.range(1));
  RunPress(state, Rig()[static_cast<size_t>(state.range(0))], options);
}
// press_03: 5 mm sphere, press_14: 2.5 mm rod, press_17: flat, press_19: a stroke,
// press_09: a 15 mm sphere (its ramp's rod candidate asked for 400 mm rods: the max_ms row).
BENCHMARK(ReconstructPress)
    ->ArgNames({"press", "models", "force_step"})
    ->ArgsProduct({{3, 9, 14, 17, 19}, {0, 3}, {0, 1}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(ReconstructPressExplainedBudget)
    ->ArgNames({"press", "budget"})
    ->ArgsProduct({{0, 3, 12, 14, 17, 19}, {0, 6}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(ReconstructPressJacobian)
    ->ArgNames({"press", "refresh"})
    ->ArgsProduct({{0, 3, 12, 14, 17, 19}, {1, 4}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace sedbridge

BENCHMARK_MAIN();
