// A hand's replay (bridge::RunHandReplay) at fingers x scan rate on 1 and 2 finger threads:
// every finger is the shipped default bridge (uskin_4x4 -> model B, fe.step contact ->
// suction_4x4) on its own bus, fed the example press; 500 Hz is the same log played five times
// faster. Each combination runs in a child process, so its peak memory (VmHWM) is its own:
// the memory of each extra finger (the leader model and its precompute shared) is the
// difference. Prints one row per run:
//   fingers, rate_Hz, threads, scans, wall_s, scans_per_s, realtime_x (log time / wall time),
//   worst finger's per-scan time p50 / p99 [ms] (the sum of the scan's stage times: what the scan
//   cost its thread; unpaced, the receive-to-publish latency would count the queue), VmHWM [MiB]
//   build/tests/bench/hand_replay_benchmark [--fingers 1,3,5] [--rates 100,500] [--threads 1,2]

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bridge/bridge_config.h"
#include "bridge/fingers.h"
#include "bridge/replay.h"
#include "bridge/scene_fe_step.h"
#include "display/display_profile.h"
#include "sensors/candump_log.h"

namespace sedbridge::bridge {
namespace {

// The example log on `fingers` buses (can0, can1, ...), its time compressed by `speedup`.
std::string HandLog(int fingers, double speedup) {
  std::ifstream in(std::string(SEDBRIDGE_SOURCE_DIR) + "/config/bridge/example_press.log");
  const std::string path = "/tmp/sedbridge_hand_bench_" + std::to_string(getpid()) + ".log";
  std::ofstream out(path);
  double t0 = -1;
  char stamp[64];
  for (std::string line; std::getline(in, line);) {
    const size_t close = line.find(')');
    const double t = std::stod(line.substr(1, close - 1));
    if (t0 < 0) t0 = t;
    std::snprintf(stamp, sizeof stamp, "(%.6f)", t0 + (t - t0) / speedup);
    const size_t bus = line.find(" can0 ");
    for (int f = 0; f < fingers; ++f) out << stamp << " can" << f << ' ' << line.substr(bus + 6) << '\n';
  }
  return path;
}

double VmHwm_MiB() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0;
}

void RunOne(int fingers, double rate_Hz, int threads) {
  SetFeThreads(1);
  BridgeConfig config = LoadBridgeConfig(DefaultBridgeConfigPath());
  for (int f = 0; f < fingers; ++f) {
    FingerConfig finger;
    finger.name = "f" + std::to_string(f);
    finger.can_interface = "can" + std::to_string(f);
    config.fingers.push_back(finger);
  }
  std::vector<HandFinger> hand;
  for (Finger& f : FingersOf(config))
    hand.push_back({f.name, f.config, LoadFingerSensorProfile(f.config),
                    display::LoadNamedDisplayProfile(f.config.display_profile), nullptr});
  const std::string log = HandLog(fingers, rate_Hz / 100.0);
  sensors::CandumpLogSource source(log);
  ReplayOptions options;
  options.finger_threads = threads;
  const HandReplayResult r = RunHandReplay(std::move(hand), source, options);
  std::remove(log.c_str());
  int64_t scans = 0;
  double p50 = 0, p99 = 0, log_s = 0;
  for (const ReplayResult& f : r.fingers) {
    scans += int64_t(f.rows.size());
    std::vector<double> ms;
    for (const ReplayRow& row : f.rows) {
      double sum = 0;
      for (double x : row.stage_ms.ms) sum += x;
      ms.push_back(sum);
    }
    std::sort(ms.begin(), ms.end());
    if (!ms.empty()) {
      p50 = std::max(p50, ms[ms.size() / 2]);
      p99 = std::max(p99, ms[std::min(ms.size() - 1, size_t(0.99 * double(ms.size())))]);
    }
    if (!f.rows.empty()) log_s = std::max(log_s, (f.rows.back().utime - f.rows.front().utime) * 1e-6);
  }
  std::printf("%7d %7.0f %7d %6lld %7.3f %11.0f %10.2f %10.3f %10.3f %9.1f\n", fingers, rate_Hz, threads,
              static_cast<long long>(scans), r.wall_s, r.wall_s > 0 ? scans / r.wall_s : 0.0,
              r.wall_s > 0 ? log_s / r.wall_s : 0.0, p50, p99, VmHwm_MiB());
  std::fflush(stdout);
}

std::vector<double> ListOf(const char* text) {
  std::vector<double> v;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) v.push_back(std::stod(item));
  return v;
}

}  // namespace
}  // namespace sedbridge::bridge

int main(int argc, char** argv) {
  std::vector<double> fingers = {1, 3, 5}, rates = {100, 500}, threads = {1, 2};
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--fingers") fingers = sedbridge::bridge::ListOf(argv[i + 1]);
    else if (key == "--rates") rates = sedbridge::bridge::ListOf(argv[i + 1]);
    else if (key == "--threads") threads = sedbridge::bridge::ListOf(argv[i + 1]);
    else {
      std::fprintf(stderr, "usage: %s [--fingers 1,3,5] [--rates 100,500] [--threads 1,2]\n", argv[0]);
      return 2;
    }
  }
  std::printf("fingers rate_Hz threads  scans  wall_s scans_per_s realtime_x scan_p50ms scan_p99ms VmHWM_MiB\n");
  std::fflush(stdout);
  for (double f : fingers)
    for (double r : rates)
      for (double t : threads) {
        const pid_t child = fork();
        if (child == 0) {
          try {
            sedbridge::bridge::RunOne(int(f), r, int(t));
          } catch (const std::exception& e) {
            std::fprintf(stderr, "error: %s\n", e.what());
            _exit(1);
          }
          _exit(0);
        }
        int status = 0;
        waitpid(child, &status, 0);
      }
  return 0;
}
