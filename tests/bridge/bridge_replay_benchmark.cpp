// Replay at maximum speed through the whole bridge on model B (scene-based, reduced and
// reconstructed-contact FE step) and B_coarse: scans/s and the
// per-scan latency (assembler emit -> command published) median / p99 as counters.
//   build/tests/bridge/bridge_replay_benchmark --benchmark_counters_tabular=true
// OMP_NUM_THREADS=1 is what the bridge commands use (--threads 1).

#include <benchmark/benchmark.h>

#include "bridge/make_fe_step.h"
#include "bridge/replay.h"
#include "bridge/scene_fe_step.h"
#include "bridge_test_util.h"
#include "sensors/candump_log.h"

namespace sedbridge::bridge {
namespace {

void BM_ReplayLog(benchmark::State& state, const std::string& model, const std::string& step,
                  const std::string& log_in_source) {
  SetFeThreads(1);
  BridgeConfig config = LoadBridgeConfig(DefaultBridgeConfigPath());
  config.model = model;
  config.fe_step = FeStepKindFromString(step);
  const std::string log = std::string(SEDBRIDGE_SOURCE_DIR) + "/" + log_in_source;
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile(config.sensor_profile);
  int64_t scans = 0;
  double wall = 0, p50 = 0, p99 = 0, max = 0;
  StageTimes stage_p50_ms;
  for (auto _ : state) {
    state.PauseTiming();
    sensors::CandumpLogSource source(log);
    auto fe = MakeFeStep(config, profile);  // model load + factorization: not timed
    ReplayOptions options;
    state.ResumeTiming();
    const ReplayResult r = RunReplay(config, profile, testing::ConfigDisplay(config), std::move(fe), source, options);
    scans += r.counters.scans;
    wall += r.wall_s;
    p50 = r.latency.p50_ms;
    p99 = r.latency.p99_ms;
    max = r.latency.max_ms;
    stage_p50_ms = r.stage_p50_ms;
  }
  state.counters["scans_per_s"] = wall > 0 ? scans / wall : 0;
  state.counters["latency_p50_ms"] = p50;
  state.counters["latency_p99_ms"] = p99;
  state.counters["latency_max_ms"] = max;
  // Median per stage (the stages this FE step has).
  for (int i = 0; i < kNumStages; ++i)
    if (stage_p50_ms.ms[size_t(i)] > 0)
      state.counters[std::string(ToString(static_cast<Stage>(i))) + "_p50_ms"] = stage_p50_ms.ms[size_t(i)];
}

void BM_ReplayExampleLog(benchmark::State& state, const std::string& model, const std::string& step) {
  BM_ReplayLog(state, model, step, "config/bridge/example_press.log");
}

BENCHMARK_CAPTURE(BM_ReplayExampleLog, B_scene, std::string("B"), std::string("scene"))
    ->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_ReplayExampleLog, B_reduced, std::string("B"), std::string("reduced"))
    ->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_ReplayExampleLog, B_contact, std::string("B"), std::string("contact"))
    ->Unit(benchmark::kMillisecond)->Iterations(3);
// The reconstructed contact on the rig's hardest press for time: a 1 mm rod
// (docs/lab-notes/2026-11-27-time-per-scan-rounds.md#s5).
BENCHMARK_CAPTURE(BM_ReplayLog, B_contact_rig_rod_1mm, std::string("B"), std::string("contact"),
                  std::string("config/sensors/rig_uskin_4x4/press_12.log"))
    ->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_ReplayExampleLog, B_coarse_scene, std::string("B_coarse"), std::string("scene"))
    ->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace sedbridge::bridge

BENCHMARK_MAIN();
