// The surface pressure (sensors/surface_pressure_inversion.h): what one scan costs.
// Run (Release build):
//   build/tests/bench/surface_pressure_benchmark
// SurfacePressureCold/<press>/<cell_um>/<max_iterations>: the peak scan of a calibration-rig press solved
//   from no warm start (the first scan a fallback answers), grid cell <cell_um> um.
// SurfacePressureStream/<press>/<cell_um>/<max_iterations>: every scan of the press in order, each warm-started
//   from the last (a run of fallback scans); time per scan = the reported time / scans.
// Counters: Newton iterations and loaded cells per solve (deterministic: the cost without
// the machine's noise).

#include <benchmark/benchmark.h>

#include <vector>

#include "common/resource_path.h"
#include "sensors/calibration_press.h"
#include "tests/bench/rig_presses.h"
#include "sensors/surface_pressure_inversion.h"

namespace sedbridge {
namespace {

using bench::Profile;
using bench::Rig;

size_t PeakScan(const sensors::CalibrationPress& press) {
  size_t peak = 0;
  double best = -1;
  for (size_t i = 0; i < press.readings_N.size(); ++i) {
    double z = 0;
    for (Eigen::Index k = 2; k < press.readings_N[i].size(); k += 3) z += press.readings_N[i][k];
    if (z > best) best = z, peak = i;
  }
  return peak;
}

sensors::SurfacePressureOptions Options(const benchmark::State& state) {
  sensors::SurfacePressureOptions o;
  o.cell_mm = 1e-3 * double(state.range(1));
  o.max_iterations = int(state.range(2));
  return o;
}

void SurfacePressureCold(benchmark::State& state) {
  const sensors::CalibrationPress& press = Rig().at(size_t(state.range(0)));
  sensors::SurfacePressureInversion inversion(Profile(), Options(state));
  const sensors::Scan& scan = press.scans.at(PeakScan(press));
  double iterations = 0, cells = 0, solves = 0;
  for (auto _ : state) {
    inversion.ResetWarmStart();
    const sensors::SurfacePressure& p = inversion.Solve(scan);
    benchmark::DoNotOptimize(p.normal_force_N);
    iterations += p.iterations, cells += p.active_cells, ++solves;
  }
  state.SetLabel(press.name);
  state.counters["iterations"] = iterations / solves;
  state.counters["cells"] = cells / solves;
}

void SurfacePressureStream(benchmark::State& state) {
  const sensors::CalibrationPress& press = Rig().at(size_t(state.range(0)));
  sensors::SurfacePressureInversion inversion(Profile(), Options(state));
  double iterations = 0, solves = 0;
  for (auto _ : state) {
    inversion.ResetWarmStart();
    for (const sensors::Scan& scan : press.scans) {
      const sensors::SurfacePressure& p = inversion.Solve(scan);
      benchmark::DoNotOptimize(p.normal_force_N);
      iterations += p.iterations, ++solves;
    }
  }
  state.SetLabel(press.name + ", " + std::to_string(press.scans.size()) + " scans");
  state.counters["iterations"] = iterations / solves;
  state.counters["scans"] = double(press.scans.size());
}

// Presses: 0 (a sphere), 12 (a rod), 21 (a punch); cells 0.5 and 1 mm; 10 and 40 iterations.
BENCHMARK(SurfacePressureCold)->ArgsProduct({{0, 12, 21}, {500, 1000}, {10, 40}})->Unit(benchmark::kMicrosecond);
BENCHMARK(SurfacePressureStream)->ArgsProduct({{0, 12, 21}, {500, 1000}, {10, 40}})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace sedbridge

BENCHMARK_MAIN();
