// A hand's replay (bridge::RunHandReplay) at fingers x scan rate on 1 and 2 finger threads:
// every finger is the shipped default bridge (uskin_4x4 -> model B, fe.step contact ->
// suction_4x4) on its own bus, fed the example press; 500 Hz is the same log played five times
// faster. Each combination runs in a child process, so its peak memory (VmHWM) is its own:
// the memory of each extra finger (the leader model and its precompute shared) is the
// difference. Prints one row per run:
//   fingers, rate_Hz, threads, scans, wall_s, scans_per_s, realtime_x (log time / wall time),
//   worst finger's per-scan time p50 / p99 [ms] (the sum of the scan's stage times, wall clock:
//   unpaced, the receive-to-publish latency would count the queue), worst finger's per-scan CPU
//   time p50 / p99 [ms] (ReplayRow::cpu_ms: what the scan cost its thread, without the time it
//   waited preempted on a shared machine), VmHWM [MiB]
//   build/tests/bench/hand_replay_benchmark [--fingers 1,3,5] [--rates 100,500] [--threads 1,2]
// Without options it runs the targets and says whether each is met:
//   5 fingers at 100 Hz on one thread: each finger's per-scan CPU p99 <= 1 ms (the wall p99
//   shown beside it);
//   4 fingers at 500 Hz on two threads: keeps real time (realtime_x >= 1);
//   memory for each extra finger: (VmHWM of 5 fingers - VmHWM of 1) / 4 at 100 Hz, one thread.

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>
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

// What a child reports to the parent (one line on a pipe): the row's numbers the targets need.
struct RowResult {
  int fingers = 0, threads = 0;
  double rate_Hz = 0, realtime_x = 0, vmhwm_MiB = 0;
  std::vector<double> finger_p99_ms, finger_cpu_p99_ms;
  bool ok = false;
};

void RunOne(int fingers, double rate_Hz, int threads, int report_fd) {
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
  double p50 = 0, p99 = 0, cpu_p50 = 0, cpu_p99 = 0, log_s = 0;
  std::string finger_p99, finger_cpu_p99;
  auto percentile = [](std::vector<double>& ms, double q) {
    std::sort(ms.begin(), ms.end());
    return ms[std::min(ms.size() - 1, size_t(q * double(ms.size())))];
  };
  for (const ReplayResult& f : r.fingers) {
    scans += int64_t(f.rows.size());
    std::vector<double> ms, cpu;
    for (const ReplayRow& row : f.rows) {
      double sum = 0;
      for (double x : row.stage_ms.ms) sum += x;
      ms.push_back(sum);
      cpu.push_back(row.cpu_ms);
    }
    if (!ms.empty()) {
      p50 = std::max(p50, percentile(ms, 0.5));
      const double own = percentile(ms, 0.99);
      p99 = std::max(p99, own);
      finger_p99 += " " + std::to_string(own);
      cpu_p50 = std::max(cpu_p50, percentile(cpu, 0.5));
      const double own_cpu = percentile(cpu, 0.99);
      cpu_p99 = std::max(cpu_p99, own_cpu);
      finger_cpu_p99 += " " + std::to_string(own_cpu);
    }
    if (!f.rows.empty()) log_s = std::max(log_s, (f.rows.back().utime - f.rows.front().utime) * 1e-6);
  }
  std::printf("%7d %7.0f %7d %6lld %7.3f %11.0f %10.2f %10.3f %10.3f %9.3f %9.3f %9.1f\n", fingers, rate_Hz, threads,
              static_cast<long long>(scans), r.wall_s, r.wall_s > 0 ? scans / r.wall_s : 0.0,
              r.wall_s > 0 ? log_s / r.wall_s : 0.0, p50, p99, cpu_p50, cpu_p99, VmHwm_MiB());
  std::fflush(stdout);
  // realtime_x, VmHWM, then each finger's wall p99, "|", each finger's CPU p99.
  const std::string report = std::to_string(r.wall_s > 0 ? log_s / r.wall_s : 0.0) + " " + std::to_string(VmHwm_MiB()) +
                             finger_p99 + " |" + finger_cpu_p99 + "\n";
  [[maybe_unused]] ssize_t n = write(report_fd, report.data(), report.size());
}

// Runs one row in a child process (its own VmHWM); its report, ok false when it failed.
RowResult RunChild(int fingers, double rate_Hz, int threads) {
  RowResult row;
  row.fingers = fingers;
  row.rate_Hz = rate_Hz;
  row.threads = threads;
  int fds[2];
  if (pipe(fds) != 0) return row;
  const pid_t child = fork();
  if (child == 0) {
    close(fds[0]);
    try {
      RunOne(fingers, rate_Hz, threads, fds[1]);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      _exit(1);
    }
    _exit(0);
  }
  close(fds[1]);
  std::string text;
  char buffer[512];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, size_t(n));
  close(fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  std::istringstream in(text);
  if (!(in >> row.realtime_x >> row.vmhwm_MiB)) return row;
  std::string word;
  bool cpu = false;
  while (in >> word) {
    if (word == "|") cpu = true;
    else (cpu ? row.finger_cpu_p99_ms : row.finger_p99_ms).push_back(std::stod(word));
  }
  row.ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  return row;
}

const RowResult* Find(const std::vector<RowResult>& rows, int fingers, double rate_Hz, int threads) {
  for (const RowResult& r : rows)
    if (r.ok && r.fingers == fingers && r.rate_Hz == rate_Hz && r.threads == threads) return &r;
  return nullptr;
}

// The targets, from the rows run (a target whose row was not run is said so).
void PrintTargets(const std::vector<RowResult>& rows) {
  std::printf("\ntargets:\n");
  if (const RowResult* r = Find(rows, 5, 100, 1)) {
    auto list = [](const std::vector<double>& ms, double* worst) {
      std::string each;
      *worst = 0;
      for (double p : ms) {
        *worst = std::max(*worst, p);
        char one[32];
        std::snprintf(one, sizeof one, " %.3f", p);
        each += one;
      }
      return each;
    };
    double worst = 0, worst_wall = 0;
    const std::string cpu = list(r->finger_cpu_p99_ms, &worst), wall = list(r->finger_p99_ms, &worst_wall);
    std::printf("  5 fingers at 100 Hz on one thread: per-scan CPU p99 by finger [ms]:%s -> %s (target <= 1 ms each; "
                "wall p99:%s)\n",
                cpu.c_str(), worst <= 1.0 ? "MET" : "NOT MET", wall.c_str());
  } else {
    std::printf("  5 fingers at 100 Hz on one thread: not run\n");
  }
  if (const RowResult* r = Find(rows, 4, 500, 2))
    std::printf("  4 fingers at 500 Hz on two threads: realtime_x %.2f -> %s (target: keeps real time, >= 1)\n",
                r->realtime_x, r->realtime_x >= 1.0 ? "MET" : "NOT MET");
  else
    std::printf("  4 fingers at 500 Hz on two threads: not run\n");
  // Memory: the largest hand against one finger, at the same rate and threads.
  const RowResult* one = nullptr;
  const RowResult* most = nullptr;
  for (const RowResult& r : rows) {
    if (!r.ok || r.rate_Hz != 100 || r.threads != 1) continue;
    if (r.fingers == 1) one = &r;
    if (r.fingers > 1 && (!most || r.fingers > most->fingers)) most = &r;
  }
  if (one && most)
    std::printf("  memory per extra finger: %.1f MiB ((VmHWM %d fingers %.1f - 1 finger %.1f) / %d, 100 Hz, one thread)\n",
                (most->vmhwm_MiB - one->vmhwm_MiB) / (most->fingers - 1), most->fingers, most->vmhwm_MiB,
                one->vmhwm_MiB, most->fingers - 1);
  else
    std::printf("  memory per extra finger: needs 1 and more fingers at 100 Hz on one thread\n");
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
  using sedbridge::bridge::RowResult;
  std::vector<double> fingers = {1, 3, 5}, rates = {100, 500}, threads = {1, 2};
  const bool grid = argc > 1;  // any option: the grid of the lists; none: the targets' rows
  bool usage = argc % 2 == 0;
  for (int i = 1; i + 1 < argc && !usage; i += 2) {
    const std::string key = argv[i];
    if (key == "--fingers") fingers = sedbridge::bridge::ListOf(argv[i + 1]);
    else if (key == "--rates") rates = sedbridge::bridge::ListOf(argv[i + 1]);
    else if (key == "--threads") threads = sedbridge::bridge::ListOf(argv[i + 1]);
    else usage = true;
  }
  if (usage) {
    std::fprintf(stderr, "usage: %s [--fingers 1,3,5] [--rates 100,500] [--threads 1,2]\n"
                         "(no options: the targets' rows, then whether each target is met)\n", argv[0]);
    return 2;
  }
  // fingers, rate, threads: the targets' rows (1 finger for the memory per extra finger).
  std::vector<std::tuple<int, double, int>> runs;
  if (grid) {
    for (double f : fingers)
      for (double r : rates)
        for (double t : threads) runs.emplace_back(int(f), r, int(t));
  } else {
    runs = {{1, 100, 1}, {5, 100, 1}, {4, 500, 1}, {4, 500, 2}};
  }
  std::printf("fingers rate_Hz threads  scans  wall_s scans_per_s realtime_x scan_p50ms scan_p99ms cpu_p50ms cpu_p99ms VmHWM_MiB\n");
  std::fflush(stdout);
  std::vector<RowResult> rows;
  for (const auto& [f, r, t] : runs) rows.push_back(sedbridge::bridge::RunChild(f, r, t));
  sedbridge::bridge::PrintTargets(rows);
  return 0;
}
