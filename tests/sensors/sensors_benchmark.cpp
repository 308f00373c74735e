// Throughput of the sensor input path, in decoded frames per second. For scale: a 1 Mbit/s
// classic CAN bus carries at most about 8,000 frames/s.
//   build-sensors/tests/sensors/sensors_benchmark

#include <benchmark/benchmark.h>

#include <sstream>

#include "common/geometry/rigid_object.h"
#include "common/yaml_reader.h"
#include "sensors/candump_log.h"
#include "sensors/scan_assembler.h"
#include "sensors/simulated/simulated_sensor.h"

namespace sedbridge::sensors {
namespace {

const char* kProfiles[] = {"uskin_4x4", "cyskin_16", "barrett_bh8_pad"};

// 2 s of a noisy sphere press, as frames.
std::vector<Frame> SimulatedFrames(const std::string& profile_name) {
  SimulatedSensorConfig c;
  c.profile = LoadSensorProfile(ResolveProfilePath(profile_name));
  c.duration_s = 2.0;
  c.noise.stddev_counts = 2;
  auto doc = config::LoadYamlString(
      "objects:\n- shape: sphere\n  radius_mm: 10\n  position_mm: [0, 0, 10.2]\n"
      "  motion: {keyframes: [{t_s: 0, offset_mm: [0,0,0]}, {t_s: 2, offset_mm: [0,0,-1.5]}]}\n",
      "bench.yaml");
  config::MapReader owner(doc.root, doc.file);
  c.objects = geometry::ParseRigidObjects(owner, "objects");
  SimulatedSensor sim(c);
  std::vector<Frame> frames;
  for (int64_t k = 0; k < sim.scan_count(); ++k) sim.ScanFrames(k, &frames);
  return frames;
}

void BM_DecodeFrames(benchmark::State& state) {
  const std::string name = kProfiles[state.range(0)];
  const SensorProfile profile = LoadSensorProfile(ResolveProfilePath(name));
  const TaxelCodec codec(profile);
  const std::vector<Frame> frames = SimulatedFrames(name);
  DecodedFrame d;
  int64_t decoded = 0;
  for (auto _ : state) {
    for (const Frame& f : frames) {
      benchmark::DoNotOptimize(codec.Decode(f, &d));
      benchmark::DoNotOptimize(d.samples[0]);
    }
    decoded += static_cast<int64_t>(frames.size());
  }
  state.SetLabel(name);
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(decoded), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DecodeFrames)->DenseRange(0, 2);

// Decode + scan assembly + calibration: what the bridge pays per frame.
void BM_AssembleScans(benchmark::State& state) {
  const std::string name = kProfiles[state.range(0)];
  const SensorProfile profile = LoadSensorProfile(ResolveProfilePath(name));
  const std::vector<Frame> frames = SimulatedFrames(name);
  std::vector<Scan> scans;
  int64_t pushed = 0, scan_count = 0;
  for (auto _ : state) {
    ScanAssembler assembler(profile);
    for (const Frame& f : frames) {
      assembler.Push(f, &scans);
      scan_count += static_cast<int64_t>(scans.size());
      scans.clear();
    }
    pushed += static_cast<int64_t>(frames.size());
  }
  state.SetLabel(name);
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(pushed), benchmark::Counter::kIsRate);
  state.counters["scans/s"] = benchmark::Counter(static_cast<double>(scan_count), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_AssembleScans)->DenseRange(0, 2);

// candump text -> frames -> scans, as `sedbridge decode` does (no file I/O).
void BM_DecodeCandumpLog(benchmark::State& state) {
  const std::string name = kProfiles[state.range(0)];
  const SensorProfile profile = LoadSensorProfile(ResolveProfilePath(name));
  std::string text;
  for (const Frame& f : SimulatedFrames(name)) AppendCandumpLine(f, &text);
  std::vector<Scan> scans;
  int64_t frames = 0;
  for (auto _ : state) {
    std::istringstream in(text);
    CandumpLogReader reader(in);
    ScanAssembler assembler(profile);
    Frame f;
    while (reader.Next(&f)) {
      assembler.Push(f, &scans);
      scans.clear();
    }
    frames += reader.frames_read();
  }
  state.SetLabel(name);
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DecodeCandumpLog)->DenseRange(0, 2);

}  // namespace
}  // namespace sedbridge::sensors

BENCHMARK_MAIN();
