// sedbridge make-log: a candump -l log from a simulated follower-sensor scene.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "app/arg_parser.h"
#include "app/command.h"
#include "sensors/candump_log.h"
#include "sensors/scan_csv.h"
#include "sensors/simulated/simulated_sensor.h"

namespace sedbridge::app {
namespace {

using namespace sedbridge::sensors;

int RunMakeLog(int argc, char** argv) {
  ArgParser args("sedbridge make-log",
                 "Simulates the follower finger's tactile sensor pressed by the scene's objects\n"
                 "(elastic-foundation pad, see sensors/simulated/simulated_sensor.h), encodes every\n"
                 "scan into CAN frames with the sensor profile and writes them as a candump -l log\n"
                 "that `sedbridge decode` reads and canplayer replays on a real bus.");
  args.Option("profile", "PROFILE", "sensor profile (shipped name or YAML path); overrides sensor.profile in the scene")
      .Option("scene", "SCENE", "simulated-sensor scene YAML (e.g. config/scenes/sensor_sphere_press.yaml)")
      .Option("out", "LOG", "candump log to write (- for stdout)")
      .Option("duration-s", "S", "override the scene's duration [s]")
      .Option("seed", "N", "override the scene's noise seed")
      .Option("interface", "NAME", "override the interface name written in the log (e.g. vcan0)")
      .Option("truth-csv", "OUT", "also write the simulated (noise-free) taxel tractions, decode's CSV layout")
      .Epilog("example:\n"
              "  sedbridge make-log --profile cyskin_16 --scene config/scenes/sensor_sphere_press.yaml --out press.log\n"
              "  canplayer -I press.log vcan0=can0     # replay on a (virtual) bus");
  if (!args.Parse(argc, argv)) return 0;

  SimulatedSensorConfig config =
      LoadSimulatedSensorScene(args.Get("scene"), args.GetOptional("profile").value_or(""));
  if (args.Has("duration-s")) {
    config.duration_s = args.GetDouble("duration-s");
    if (!(config.duration_s > 0 && config.duration_s <= kMaxSimulatedDuration_s))
      throw UsageError("--duration-s must be in (0, 86400]");
  }
  if (args.Has("seed")) config.noise.seed = static_cast<uint64_t>(args.GetInt("seed"));
  if (args.Has("interface")) {
    config.interface = args.Get("interface");
    if (config.interface.empty() || config.interface.size() >= kInterfaceNameMax)
      throw UsageError("--interface needs 1..15 characters");
  }
  const std::string out_path = args.Get("out");
  std::ofstream file;
  std::ostream* out = &std::cout;
  if (out_path != "-") {
    file.open(out_path);
    if (!file) throw std::runtime_error("cannot write " + out_path);
    out = &file;
  }
  std::ofstream truth;
  if (auto path = args.GetOptional("truth-csv")) {
    truth.open(*path);
    if (!truth) throw std::runtime_error("cannot write " + *path);
    truth << ScanCsvHeader(config.profile);
  }

  SimulatedSensor sim(config);
  CandumpLogWriter writer(*out);
  std::vector<Frame> frames;
  std::string row;
  const int64_t scans = sim.scan_count();
  const SensorProfile& p = config.profile;
  double peak_Pa = 0;
  for (int64_t k = 0; k < scans; ++k) {
    frames.clear();
    sim.ScanFrames(k, &frames);
    for (const Frame& f : frames) writer.Write(f);
    const TaxelTractions tr = sim.Evaluate(sim.ScanTime_s(k));
    for (double v : tr.pressure_Pa) peak_Pa = std::max(peak_Pa, v);
    if (truth.is_open()) {
      Scan s;
      s.sequence = k;
      s.utime = config.start_utime + static_cast<int64_t>(std::llround(sim.ScanTime_s(k) * 1e6));
      s.complete = true;
      s.num_taxels = p.taxel_count;
      s.num_axes = p.axes;
      s.pressure_Pa = tr.pressure_Pa;
      s.shear_x_Pa = tr.shear_x_Pa;
      s.shear_y_Pa = tr.shear_y_Pa;
      s.valid.assign(p.taxel_count, 1);
      row.clear();
      AppendScanCsvRow(s, &row);
      truth << row;
    }
    if (scans >= 1000 && (k + 1) % (scans / 10) == 0)
      std::fprintf(stderr, "  %lld/%lld scans\n", static_cast<long long>(k + 1), static_cast<long long>(scans));
  }
  writer.Flush();
  if (out_path != "-") {
    std::printf("wrote %s: %lld scans, %lld frames (%lld dropped, %lld bits flipped), %s, %.1f s at %g Hz, "
                "peak pressure %.1f kPa\n",
                out_path.c_str(), static_cast<long long>(scans), static_cast<long long>(writer.frames_written()),
                static_cast<long long>(sim.frames_dropped()), static_cast<long long>(sim.bits_flipped()),
                p.name.c_str(), config.duration_s, p.scan_rate_Hz, peak_Pa * 1e-3);
    if (truth.is_open()) std::printf("wrote %s\n", args.Get("truth-csv").c_str());
  }
  return 0;
}

}  // namespace
}  // namespace sedbridge::app

SEDBRIDGE_COMMAND(make_log, "make-log", "write a candump log from a simulated tactile-sensor scene",
                  &sedbridge::app::RunMakeLog);
