// sedbridge replay: a candump log through the whole bridge, deterministically.

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "app/arg_parser.h"
#include "app/command.h"
#include "app/stop_signals.h"
#include "app/plot_runner.h"
#include "app/replay_output_options.h"
#include "bridge/bridge_config.h"
#include "bridge/replay.h"
#include "bridge/scene_fe_step.h"
#include "config/resource_path.h"
#include "sensors/candump_log.h"

namespace sedbridge::app {
namespace {

using namespace sedbridge::bridge;

void PrintReplaySummary(const ReplayResult& r, const std::string& out) {
  const PipelineCounters& c = r.counters;
  std::printf("%s\n", r.fe_description.c_str());
  std::printf("scans: %lld (stepped %lld, rejected %lld, FE failures %lld), invalid taxel readings %lld, "
              "NaN values caught %lld\n",
              static_cast<long long>(c.scans), static_cast<long long>(c.steps), static_cast<long long>(c.scans_rejected),
              static_cast<long long>(c.fe_failures), static_cast<long long>(c.invalid_taxels),
              static_cast<long long>(c.nonfinite_values));
  std::printf("frames: %lld (rejected %lld, partial scans %lld, sensor scans dropped %lld), log bad lines %lld\n",
              static_cast<long long>(r.bad_frames.frames), static_cast<long long>(r.bad_frames.rejected()),
              static_cast<long long>(r.bad_frames.scans_partial), static_cast<long long>(r.bad_frames.scans_dropped),
              static_cast<long long>(r.source_stats.bad_lines));
  if (r.peak_index >= 0) {
    const ReplayRow& p = r.rows[size_t(r.peak_index)];
    std::printf("peak: scan %d at t = %.3f s: force %.3f N (FE applied %.3f N), max Merkel SED %.1f Pa, max command "
                "%.2f %s\n",
                r.peak_index, (p.utime - r.rows.front().utime) * 1e-6, p.total_force_N, p.applied_force_N,
                p.max_sed_Pa, p.max_command, r.display_unit.c_str());
  }
  std::printf("timing: setup %.2f s; %lld scans in %.3f s = %.0f scans/s; latency median %.3f ms, p99 %.3f ms, max "
              "%.3f ms\n",
              r.setup_s, static_cast<long long>(c.scans), r.wall_s, r.wall_s > 0 ? c.scans / r.wall_s : 0.0,
              r.latency.p50_ms, r.latency.p99_ms, r.latency.max_ms);
  std::printf("LCM: %lld messages published (%lld errors)\n", static_cast<long long>(r.published),
              static_cast<long long>(r.publish_errors));
  if (!out.empty()) std::printf("wrote %s/{summary.csv, peak_merkel_sed.csv, peak_command.csv, peak_taxels.csv, bridge.lcmlog}\n", out.c_str());
}

int RunReplayCommand(int argc, char** argv) {
  ArgParser args("sedbridge replay",
                 "Replays a candump log of the follower's tactile sensor through the whole bridge:\n"
                 "scans -> pressure boundary condition -> FE step -> Merkel-layer SED -> display\n"
                 "commands (safety-limited) -> LCM. Every scan is processed; the output is stamped with\n"
                 "the log's time, so two runs write the same files (only the measured latency differs).\n"
                 "SIGINT, SIGTERM, SIGHUP or SIGQUIT stop the run: display to zero, files written, exit 128 + signal.");
  args.Positional("LOG", "candump -l log (e.g. config/bridge/example_press.log)")
      .Option("config", "BRIDGE.yaml", "bridge config", "config/bridge/default.yaml")
      .Option("speed", "S|max", "max = as fast as possible; 1 = recorded timing; 2 = twice as fast", "max")
      .Option("out", "DIR", "output folder", "out/replay")
      .Option("lcm-url", "URL", "also publish live on this LCM URL (e.g. udpm://239.255.76.67:7667?ttl=0)", "memq://")
      .Option("threads", "N", "OpenMP threads for the FE step (1 is fastest for a small model on a busy machine)", "1")
      .Option("vtu-every", "N", "also write frames.pvd + frame_*.vtu every N scans (ParaView)", "0")
      .Flag("no-plots", "write CSV and the LCM log only")
      .Flag("quiet", "no progress lines")
      .Epilog(
          "outputs in DIR:\n"
          "  summary.csv           one row per scan: utime,total_force_N,applied_force_N,max_sed_Pa,max_command,\n"
          "                        latency_ms,stepped,invalid_taxels\n"
          "  bridge.lcmlog         TACTILE_SCAN, FINGERTIP_SED, DISPLAY_COMMAND, BRIDGE_STATUS (lcm-logplayer)\n"
          "  peak_merkel_sed.csv   Merkel-layer SED at the scan of peak SED (pad frame, mm)\n"
          "  peak_command.csv      display command at that scan; peak_taxels.csv: the taxel pressures\n"
          "  bridge_*.png          SED map + display frame at peak, force and max SED over time\n"
          "  frames.pvd, frame_*.vtu  with --vtu-every N: deformation, traction, Merkel SED (ParaView)\n\n"
          "example:\n  sedbridge replay config/bridge/example_press.log --out out/replay");
  if (!args.Parse(argc, argv)) return 0;
  StopSignals signals;  // SIGINT/TERM/HUP/QUIT end the run through its normal exit (zero, log closed)

  const std::string config_path = config::ResolveResource(args.Get("config"));
  const BridgeConfig config = LoadBridgeConfig(config_path);
  sensors::PlaybackOptions playback;
  const std::string speed = args.Get("speed");
  if (speed != "max") {
    playback.speed = args.GetDouble("speed");
    if (!(playback.speed > 0 && std::isfinite(playback.speed))) throw UsageError("--speed must be > 0 or max");
  }
  SetFeThreads(static_cast<int>(args.GetInt("threads")));
  const std::string log_path = config::ResolveResource(args.Get("LOG"));
  sensors::CandumpLogSource source(log_path, playback);
  ReplayOptions options = ReadReplayOutputOptions(args, config);
  options.stop = &signals.flag();
  options.can_interface = config.can_interface;  // sensor.interface: frames of other buses are not this sensor's
  if (speed != "max") {
    options.paced_speed = playback.speed;  // live: tick the display's watchdog through pauses
    options.idle_tick_period_us = static_cast<int64_t>(1e6 / config.tick_Hz);
  }
  std::printf("replay %s with %s (sensor %s, model %s/%s, display %s)\n", log_path.c_str(), config_path.c_str(),
              config.sensor_profile.c_str(), config.model.c_str(), config.preset.c_str(),
              config.display_profile.c_str());
  std::fflush(stdout);
  const ReplayResult result = RunReplay(config, source, options);
  PrintReplaySummary(result, options.out_dir);
  if (signals.signal_number()) {
    std::printf("stopped by %s: display driven to zero, log closed\n", SignalName(signals.signal_number()));
    return signals.ExitCode(0);
  }
  if (result.rows.empty()) std::printf("warning: the log produced no scans (wrong sensor profile?)\n");
  if (result.bad_frames.other_interface > 0)
    std::printf("note: %lld frames from other interfaces than '%s' (sensor.interface) were ignored\n",
                static_cast<long long>(result.bad_frames.other_interface), options.can_interface.c_str());
  if (!args.GetFlag("no-plots") && !result.rows.empty()) {
    if (RunPlotScript("plot_bridge.py", {options.out_dir, result.display_unit}))
      std::printf("plots: %s/bridge_peak.png, %s/bridge_timeline.png\n", options.out_dir.c_str(),
                  options.out_dir.c_str());
  }
  return 0;
}

}  // namespace
}  // namespace sedbridge::app

SEDBRIDGE_COMMAND(replay, "replay", "replay a candump log through the bridge (scans -> FE -> SED -> display -> LCM)",
                  &sedbridge::app::RunReplayCommand);
