// sedbridge replay: a candump log through the whole bridge, deterministically.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>

#include "app/arg_parser.h"
#include "app/command.h"
#include "app/hand_replay_report.h"
#include "app/lcm_url.h"
#include "app/stop_signals.h"
#include "app/plot_runner.h"
#include "app/replay_output_options.h"
#include "bridge/bridge_config.h"
#include "bridge/fingers.h"
#include "bridge/replay.h"
#include "bridge/scene_fe_step.h"
#include "common/resource_path.h"
#include "display/display_profile.h"
#include "sensors/candump_log.h"
#include "sensors/interface_filter_source.h"

namespace sedbridge::app {
namespace {

using namespace sedbridge::bridge;

std::string JoinNames(const std::set<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// The reason a replay made no scan, in the words a user can act on.
std::string WhyNoScans(const sensors::CandumpLogSource& log, const sensors::InterfaceFilterSource& source,
                       const std::string& profile) {
  const sensors::CandumpLogReader& r = log.reader();
  if (r.frames_read() == 0) {
    if (r.bad_line_count() == 0) return r.name() + " holds no CAN frames (empty log)";
    std::string why = r.name() + " is not a candump -l log: none of its " + std::to_string(r.bad_line_count()) +
                      " lines is a CAN frame";
    if (!r.bad_lines().empty())
      why += " (line " + std::to_string(r.bad_lines().front().line_number) + ": " + r.bad_lines().front().reason + ")";
    return why;
  }
  if (source.Stats().frames == 0)
    return "none of the " + std::to_string(r.frames_read()) + " frames is on the chosen interface (the log has: " +
           JoinNames(source.interfaces_seen()) + ")";
  return std::to_string(source.Stats().frames) + " frames, but none of them made a scan of sensor profile '" + profile +
         "' (a different sensor? try --profile, or `sedbridge decode --profile NAME LOG` to see the counts)";
}

// A hand (`fingers:` in the config): every finger's frames from the one log, routed by
// interface and CAN id; a summary and files per finger (DIR/<finger>/).
int ReplayHand(const ArgParser& args, const BridgeConfig& config, sensors::FrameSource& log, ReplayOptions options,
               const StopSignals& signals) {
  if (args.Has("profile") || args.Has("interface"))
    throw UsageError("--profile and --interface are one finger's: a config with 'fingers:' names each finger's own");
  std::vector<HandFinger> fingers = LoadHandFingers(config);
  const HandReplayResult hand = RunHandReplay(std::move(fingers), log, options);
  return ReportHandReplay("replay", hand, options.out_dir, args.GetFlag("no-plots"), signals);
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
      .Option("profile", "SENSOR", "sensor profile: shipped name or YAML (overrides the config's sensor.profile)")
      .Option("interface", "NAME", "use only this interface's frames (logs from `candump -l any` mix several)")
      .Option("speed", "S|max", "max = as fast as possible; 1 = recorded timing; 2 = twice as fast", "max")
      .Option("out", "DIR", "output folder", "out/replay")
      .Option("lcm-url", "URL", LcmUrlHelp("memq:// (the log file only); e.g. udpm://239.255.76.67:7667?ttl=1"))
      .Option("threads", "N", "OpenMP threads for the FE step (1 is fastest for a small model on a busy machine)", "1")
      .Option("finger-threads", "N", "a config with fingers: threads the fingers run on (the output is the same for any N)", "1")
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
          "  peak_display_sed.csv  display.rendering inverse: the SED the display delivers at that scan (full FE)\n"
          "  peak_sa1_rate_estimate.csv  electrotactile display (no mechanical load): the SA1 rate ESTIMATE at\n"
          "                        each electrode from the SED asked at that scan (display/sa1_rate_estimate.h)\n"
          "  bridge_*.png          SED map + display frame at peak, force and max SED over time\n"
          "  frames.pvd, frame_*.vtu  with --vtu-every N: reference mesh + displacement_mm (ParaView: Warp By\n"
          "                        Vector, scale 1), Merkel SED; Time = seconds since the first scan\n\n"
          "example:\n  sedbridge replay config/bridge/example_press.log --out out/replay\n"
          "exit status: 0 ok; 1 when the log is not a candump -l log or none of its frames makes a\n"
          "scan of the sensor profile (the reason is printed); 2 usage.");
  if (!args.Parse(argc, argv)) return 0;
  StopSignals signals;  // SIGINT/TERM/HUP/QUIT end the run through its normal exit (zero, log closed)

  const std::string config_path = config::ResolveResource(args.Get("config"));
  BridgeConfig config = LoadBridgeConfig(config_path);
  if (auto profile = args.GetOptional("profile")) config.sensor_profile = *profile;
  sensors::PlaybackOptions playback;
  const std::string speed = args.Get("speed");
  if (speed != "max") {
    playback.speed = args.GetDouble("speed");
    if (!(playback.speed > 0 && std::isfinite(playback.speed))) throw UsageError("--speed must be > 0 or max");
  }
  SetFeThreads(static_cast<int>(args.GetInt("threads")));
  const std::string log_path = config::ResolveResource(args.Get("LOG"));
  sensors::CandumpLogSource log(log_path, playback);
  if (!config.fingers.empty()) {
    ReplayOptions options = ReadReplayOutputOptions(args, config);
    options.stop = &signals.flag();
    options.finger_threads = static_cast<int>(args.GetInt("finger-threads"));
    if (options.finger_threads < 1) throw UsageError("--finger-threads must be >= 1");
    if (speed != "max") options.paced_speed = playback.speed, options.idle_tick_period_us = int64_t(1e6 / config.tick_Hz);
    std::printf("replay %s with %s (%zu fingers)\n", log_path.c_str(), config_path.c_str(), config.fingers.size());
    return ReplayHand(args, config, log, std::move(options), signals);
  }
  sensors::InterfaceFilterSource source(log, args.GetOptional("interface").value_or(""));
  ReplayOptions options = ReadReplayOutputOptions(args, config);
  options.stop = &signals.flag();
  // One bus filter: --interface picks the sensor's bus of a multi-bus log (frames of other
  // buses are counted as other_interface); without it every frame is read and a mixed log
  // is reported below. The config's sensor.interface names the live bus of `run`.
  options.can_interface = args.GetOptional("interface").value_or("");
  if (speed != "max") {
    options.paced_speed = playback.speed;  // live: tick the display's watchdog through pauses
    options.idle_tick_period_us = static_cast<int64_t>(1e6 / config.tick_Hz);
  }
  std::printf("replay %s with %s (sensor %s, model %s/%s, display %s)\n", log_path.c_str(), config_path.c_str(),
              config.sensor_profile.c_str(), config.model.c_str(), config.preset.c_str(),
              config.display_profile.c_str());
  std::fflush(stdout);
  const ReplayResult result =
      RunReplay(config, sensors::LoadNamedSensorProfile(config.sensor_profile),
                display::LoadNamedDisplayProfile(config.display_profile), nullptr, source, options);
  PrintReplaySummary(result, options.out_dir);
  if (signals.signal_number()) {
    std::printf("stopped by %s: display driven to zero, log closed\n", SignalName(signals.signal_number()));
    return signals.ExitCode(0);
  }
  if (source.interfaces_seen().size() > 1 && !args.Has("interface"))
    std::printf("warning: the log mixes interfaces (%s) in one sensor's scans; --interface NAME keeps one "
                "(sensor.interface of the config: %s)\n",
                JoinNames(source.interfaces_seen()).c_str(), config.can_interface.c_str());
  if (result.rows.empty()) {
    std::fprintf(stderr, "sedbridge replay: error: %s\n", WhyNoScans(log, source, config.sensor_profile).c_str());
    return 1;
  }
  if (result.bad_frames.other_interface > 0)
    std::printf("note: %lld frames from other interfaces than '%s' (sensor.interface) were ignored\n",
                static_cast<long long>(result.bad_frames.other_interface), options.can_interface.c_str());
  if (!args.GetFlag("no-plots") && !result.rows.empty()) {
    if (RunPlotScript("plot_bridge.py", PlotBridgeArgs(options.out_dir, result)))
      std::printf("plots: %s/bridge_peak.png, %s/bridge_timeline.png\n", options.out_dir.c_str(),
                  options.out_dir.c_str());
  }
  return 0;
}

}  // namespace
}  // namespace sedbridge::app

SEDBRIDGE_COMMAND(replay, "replay", "replay a candump log through the bridge (scans -> FE -> SED -> display -> LCM)",
                  &sedbridge::app::RunReplayCommand);
