// The inverse renderer's time per scan on a press that moves between scans (warm start), on
// a synthetic influence the size of model B's Merkel layer (469 vertices) for 16, 64 and 256
// actuators. One thread. Run: build/tests/bench/render_benchmark
#include <benchmark/benchmark.h>

#include <cmath>

#include "render/inverse_renderer.h"
#include "render_test_util.h"

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

}  // namespace

BENCHMARK_MAIN();
