// The inverse renderer's time per scan on a press that moves between scans (warm start):
//   - BM_InverseRenderMovingPress: a synthetic influence the size of model B's Merkel layer
//     (469 vertices) for 16, 64 and 256 actuators;
//   - BM_InverseRenderOnModelB/<display>: the display's influence on model B (face contact),
//     targets the SED of a 5 mm sphere pressed at 0.5 N on model B, sliding 4 mm across the
//     pad in 20 scans (the precompute takes seconds to minutes: compliance cache in
//     out/cache, run from the repository root).
// One thread. Run: build/tests/bench/render_benchmark
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include <memory>
#include <vector>

#include "common/geometry/signed_distance_field.h"
#include "display/display_profile.h"
#include "model/fingertip_model.h"
#include "render/display_rendering.h"
#include "render/inverse_renderer.h"
#include "render_test_util.h"
#include "scene/fingertip_compliance.h"

namespace {

using sedbridge::render::DisplayInfluence;
using sedbridge::render::InverseRenderer;

void BM_InverseRenderMovingPress(benchmark::State& state) {
  const int actuators = int(state.range(0));
  InverseRenderer renderer(DisplayInfluence(sedbridge::render::testing::SyntheticInfluence(actuators, 470, 1e-3)),
                           Eigen::VectorXd::Constant(actuators, 20.0));
  // 100 scans of a press sliding across the display: commands a bump that moves.
  std::vector<Eigen::VectorXd> targets;
  for (int k = 0; k < 100; ++k) {
    Eigen::VectorXd u(actuators);
    for (int a = 0; a < actuators; ++a) {
      const double d = (double(a) / actuators - 0.2 - 0.006 * k) * 8.0;
      u[a] = 15.0 * std::exp(-d * d);
    }
    Eigen::VectorXd sed;
    renderer.influence().Sed(u, sed);
    targets.push_back(sed - renderer.influence().preload_sed_Pa());
  }
  size_t k = 0;
  int iterations = 0, evaluations = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(renderer.Render(targets[k]).data());
    iterations += renderer.last().iterations;
    evaluations += renderer.last().evaluations;
    k = (k + 1) % targets.size();
  }
  state.counters["gn_iterations"] = double(iterations) / double(state.iterations());
  state.counters["sed_evaluations"] = double(evaluations) / double(state.iterations());
}
BENCHMARK(BM_InverseRenderMovingPress)->Arg(16)->Arg(64)->Arg(256)->Unit(benchmark::kMicrosecond);

const char* const kDisplays[] = {"suction_4x4", "pin_6x4", "suction_8x8", "pin_8x8"};

// The sliding sphere's SED on model B, computed once for every display.
const std::vector<Eigen::VectorXd>& SphereTargets(const sedbridge::model::FingertipModel& model) {
  static std::vector<Eigen::VectorXd> targets;
  if (!targets.empty()) return targets;
  sedbridge::scene::FingertipComplianceOptions options;
  options.contact.cache_dir = "out/cache";
  sedbridge::scene::FingertipCompliance leader(model, options);
  for (int k = 0; k < 20; ++k) {
    const double x_m = (-2.0 + 0.2 * k) * 1e-3, radius_m = 5e-3;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(x_m, 0.5e-3, radius_m);
    sedbridge::geometry::RigidObject sphere{"sphere", std::make_shared<sedbridge::geometry::SphereSdf>(radius_m),
                                            sedbridge::geometry::Trajectory(pose)};
    leader.ResetWarmStart();
    if (leader.PressToForce({sphere}, 0.5).reached) targets.push_back(leader.sed_Pa());
  }
  return targets;
}

void BM_InverseRenderOnModelB(benchmark::State& state) {
  static const sedbridge::model::FingertipModel model = sedbridge::model::LoadFingertipModel("B");
  const char* name = kDisplays[state.range(0)];
  sedbridge::render::DisplayRenderingOptions options;
  options.cache_dir = "out/cache";
  options.prune_relative = std::pow(10.0, -double(state.range(1)));
  options.renderer.max_iterations = int(state.range(2));
  const bool grouped = state.range(3) != 0;  // dropped share 10^-range(3); 0: the elements
  std::unique_ptr<sedbridge::render::DisplayRendering> rendering, exact;
  try {
    options.fit_reduction = 0;
    if (grouped) exact = std::make_unique<sedbridge::render::DisplayRendering>(
        model, sedbridge::display::LoadNamedDisplayProfile(name), options);
    options.fit_reduction = grouped ? std::pow(10.0, -double(state.range(3))) : 0.0;
    rendering = std::make_unique<sedbridge::render::DisplayRendering>(
        model, sedbridge::display::LoadNamedDisplayProfile(name), options);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  const std::vector<Eigen::VectorXd>& targets = SphereTargets(model);
  if (targets.empty()) {
    state.SkipWithError("no sphere press reached its force");
    return;
  }
  size_t k = 0;
  int iterations = 0, evaluations = 0;
  std::vector<double> misfit;  // rel L2 of the added SED the commands give (influence) vs the target
  Eigen::VectorXd sed;
  std::vector<double> render_us;  // each render's wall time, for the p99
  std::vector<int> render_evaluations;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(rendering->Render(targets[k]).data());
    render_us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count());
    iterations += rendering->last().iterations;
    evaluations += rendering->last().evaluations;
    render_evaluations.push_back(rendering->last().evaluations);
    state.PauseTiming();
    const sedbridge::render::DisplayInfluence& judge = (exact ? exact : rendering)->influence();
    judge.Sed(rendering->renderer().commands(), sed);
    misfit.push_back((sed - judge.preload_sed_Pa() - targets[k]).norm() / targets[k].norm());
    state.ResumeTiming();
    k = (k + 1) % targets.size();
  }
  std::nth_element(misfit.begin(), misfit.begin() + long(misfit.size() / 2), misfit.end());
  state.SetLabel(name);
  state.counters["actuators"] = rendering->num_actuators();
  state.counters["elements"] = rendering->influence().num_active_elements();
  state.counters["of_elements"] = rendering->influence().num_elements();
  state.counters["vertices"] = double(rendering->influence().active_vertices().size());
  state.counters["precompute_s"] = rendering->precompute_s();
  state.counters["gn_iterations"] = double(iterations) / double(state.iterations());
  state.counters["sed_evaluations"] = double(evaluations) / double(state.iterations());
  state.counters["median_rel_l2"] = misfit[misfit.size() / 2];
  std::sort(render_us.begin(), render_us.end());
  state.counters["p99_us"] = render_us[std::min(render_us.size() - 1, size_t(0.99 * double(render_us.size())))];
  std::sort(render_evaluations.begin(), render_evaluations.end());
  state.counters["p99_evaluations"] = render_evaluations[std::min(render_evaluations.size() - 1, size_t(0.99 * double(render_evaluations.size())))];
  state.counters["max_evaluations"] = render_evaluations.back();
}
// Arguments: display, prune exponent, iterations allowed a scan (fewer buy time per scan
// with the fit, measured by median_rel_l2; 3 is the product's default), fit reduction.
// p99_us: each render's wall time, 99th percentile; p99_evaluations, max_evaluations: SED
// evaluations a render. Last argument k: the fit on the influence reduced per vertex
// (render/reduced_vertex_strain.h, dropped share 10^-k; 2 is the product's default), its
// commands judged (median_rel_l2) by the elements' influence; 0: the elements themselves.
// Suction 4x4 is evaluated from exact vertex forms, never reduced.
BENCHMARK(BM_InverseRenderOnModelB)->ArgsProduct({{0}, {4}, {1, 3, 8}, {0}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_InverseRenderOnModelB)->ArgsProduct({{1, 2, 3}, {4}, {1, 3, 8}, {0, 2}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_InverseRenderOnModelB)->ArgsProduct({{1, 3}, {4}, {1, 3}, {3, 4}})->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
