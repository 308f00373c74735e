// sedbridge simulate: the simulated follower sensor -> encoded CAN frames -> the same decoder
// and bridge pipeline as replay and run.

#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

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
#include "sensors/merged_frame_source.h"
#include "sensors/simulated/simulated_sensor.h"

namespace sedbridge::app {
namespace {

using namespace sedbridge::bridge;

// --duration-s over the scene's.
void ApplyDuration(const ArgParser& args, sensors::SimulatedSensorConfig* sim) {
  if (!args.Has("duration-s")) return;
  sim->duration_s = args.GetDouble("duration-s");
  if (!(sim->duration_s > 0 && sim->duration_s <= sensors::kMaxSimulatedDuration_s))
    throw UsageError("--duration-s must be in (0, 86400]");
}

// --finger-scenes "thumb=a.yaml,index=b.yaml": a finger's own scene, by name.
std::map<std::string, std::string> FingerScenes(const std::string& list, const std::vector<HandFinger>& fingers) {
  std::map<std::string, std::string> scenes;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ',');) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      throw UsageError("--finger-scenes: '" + item + "' is not NAME=SCENE");
    const std::string name = item.substr(0, eq);
    std::string known;
    bool found = false;
    for (const HandFinger& f : fingers) known += (known.empty() ? "" : ", ") + f.name, found |= f.name == name;
    if (!found) throw UsageError("--finger-scenes: no finger '" + name + "' in the config (its fingers: " + known + ")");
    if (!scenes.emplace(name, item.substr(eq + 1)).second)
      throw UsageError("--finger-scenes: finger '" + name + "' given twice");
  }
  return scenes;
}

// A hand (`fingers:`): one simulated sensor per finger, on the finger's bus with its ids
// (sensor.id_offset applied), pressed as its scene says (its own from --finger-scenes, else
// SCENE), merged in time order into one stream of frames and run through the hand's replay
// (bridge::RunHandReplay): the same routing, pipelines and files as `replay` of a recording
// of that hand.
int SimulateHand(const ArgParser& args, const BridgeConfig& config, const std::string& scene_path,
                 const StopSignals& signals) {
  if (args.Has("profile"))
    throw UsageError("--profile is one finger's: a config with 'fingers:' names each finger's own sensor");
  std::vector<HandFinger> fingers = LoadHandFingers(config);
  const std::map<std::string, std::string> own = FingerScenes(args.GetOptional("finger-scenes").value_or(""), fingers);
  std::vector<std::unique_ptr<sensors::FrameSource>> sources;
  for (const HandFinger& f : fingers) {
    const auto it = own.find(f.name);
    const std::string path = it == own.end() ? scene_path : config::ResolveResource(it->second);
    sensors::SimulatedSensorConfig sim = sensors::LoadSimulatedSensorScene(path, f.config.sensor_profile);
    ApplyDuration(args, &sim);
    sim.profile = f.profile;  // the finger's CAN ids (sensor.id_offset)
    sim.interface = f.config.can_interface;
    std::printf("finger %s: simulated %s at %g Hz for %.2f s on %s, scene %s\n", f.name.c_str(), sim.profile.name.c_str(),
                sim.profile.scan_rate_Hz, sim.duration_s, sim.interface.c_str(), path.c_str());
    sources.push_back(std::make_unique<sensors::SimulatedSensorSource>(std::move(sim)));
  }
  std::fflush(stdout);
  sensors::MergedFrameSource source(std::move(sources));
  ReplayOptions options = ReadReplayOutputOptions(args, config);
  options.stop = &signals.flag();
  options.finger_threads = static_cast<int>(args.GetInt("finger-threads"));
  if (options.finger_threads < 1) throw UsageError("--finger-threads must be >= 1");
  const HandReplayResult hand = RunHandReplay(std::move(fingers), source, options);
  return ReportHandReplay("simulate", hand, options.out_dir, args.GetFlag("no-plots"), signals);
}

int RunSimulateCommand(int argc, char** argv) {
  ArgParser args("sedbridge simulate",
                 "Runs the simulated follower sensor of a scene (sensors/simulated) and feeds its encoded\n"
                 "CAN frames through the same decoder, scan assembler and bridge pipeline as `replay`\n"
                 "and `run`: pressure boundary condition -> FE step -> Merkel SED -> display -> LCM.\n"
                 "The sensor profile comes from --profile, else the bridge config (the scene's sensor.profile\n"
                 "is replaced). A config with `fingers:` (a hand) simulates one sensor per finger, each with\n"
                 "the finger's profile, bus and ids: SCENE presses every finger alike, --finger-scenes gives a\n"
                 "finger its own scene (object and timing); their frames are merged in time order and run as\n"
                 "`replay` runs a hand's log, with each finger's files in DIR/<finger>/.");
  args.Positional("SCENE", "simulated-sensor scene YAML (e.g. config/scenes/sensor_sphere_press.yaml); a hand: every finger's "
                           "unless --finger-scenes names its own")
      .Option("config", "BRIDGE.yaml", "bridge config", "config/bridge/default.yaml")
      .Option("profile", "SENSOR", "sensor profile: shipped name or YAML (overrides the config's sensor.profile)")
      .Option("out", "DIR", "output folder (same files as replay)", "out/simulate")
      .Option("duration-s", "S", "override the scene's duration [s]")
      .Option("lcm-url", "URL", LcmUrlHelp("memq:// (the log file only)"))
      .Option("threads", "N", "OpenMP threads for the FE step", "1")
      .Option("finger-scenes", "NAME=SCENE,...", "a config with fingers: these fingers' own scenes (the others take SCENE)")
      .Option("finger-threads", "N", "a config with fingers: threads the fingers run on (the output is the same for any N)", "1")
      .Option("vtu-every", "N", "also write frames.pvd + frame_*.vtu every N scans (ParaView)", "0")
      .Flag("no-plots", "write CSV and the LCM log only")
      .Flag("quiet", "no progress lines")
      .Epilog("examples:\n  sedbridge simulate config/scenes/sensor_edge_slide.yaml --out out/edge\n"
              "  sedbridge simulate config/bridge/hand/thumb_scene.yaml --config config/bridge/example_hand.yaml \\\n"
              "      --finger-scenes index=config/bridge/hand/index_scene.yaml,middle=config/bridge/hand/middle_scene.yaml \\\n"
              "      --out out/simulate_hand");
  if (!args.Parse(argc, argv)) return 0;
  StopSignals signals;  // SIGINT/TERM/HUP/QUIT end the run through its normal exit (zero, log closed)

  SetFeThreads(static_cast<int>(args.GetInt("threads")));
  const std::string config_path = config::ResolveResource(args.Get("config"));
  BridgeConfig config = LoadBridgeConfig(config_path);
  const std::string scene_path = config::ResolveResource(args.Get("SCENE"));
  if (!config.fingers.empty()) {
    std::printf("simulate %s with %s (%zu fingers)\n", scene_path.c_str(), config_path.c_str(), config.fingers.size());
    return SimulateHand(args, config, scene_path, signals);
  }
  if (args.Has("finger-scenes")) throw UsageError("--finger-scenes needs a config with 'fingers:' (a hand)");
  if (auto profile = args.GetOptional("profile")) config.sensor_profile = *profile;
  sensors::SimulatedSensorConfig sim = sensors::LoadSimulatedSensorScene(scene_path, config.sensor_profile);
  ApplyDuration(args, &sim);
  const sensors::SensorProfile profile = sim.profile;
  sensors::SimulatedSensorSource source(sim);
  ReplayOptions options = ReadReplayOutputOptions(args, config);
  options.stop = &signals.flag();
  options.can_interface = sim.interface;
  std::printf("simulate %s: sensor %s at %g Hz for %.2f s -> model %s/%s -> display %s\n", scene_path.c_str(),
              profile.name.c_str(), profile.scan_rate_Hz, sim.duration_s, config.model.c_str(), config.preset.c_str(),
              config.display_profile.c_str());
  std::fflush(stdout);
  const ReplayResult result =
      RunReplay(config, profile, display::LoadNamedDisplayProfile(config.display_profile), nullptr, source, options);
  std::printf("%s\n", result.fe_description.c_str());
  if (result.rows.empty()) {
    std::fprintf(stderr, "sedbridge simulate: error: the simulated sensor made no scan (%lld frames, %lld rejected)\n",
                 static_cast<long long>(result.bad_frames.frames), static_cast<long long>(result.bad_frames.rejected()));
    return 1;
  }
  std::printf("scans: %lld (stepped %lld, rejected %lld); frames %lld (rejected %lld, partial scans %lld)\n",
              static_cast<long long>(result.counters.scans), static_cast<long long>(result.counters.steps),
              static_cast<long long>(result.counters.scans_rejected), static_cast<long long>(result.bad_frames.frames),
              static_cast<long long>(result.bad_frames.rejected()),
              static_cast<long long>(result.bad_frames.scans_partial));
  if (result.peak_index >= 0) {
    const ReplayRow& p = result.rows[size_t(result.peak_index)];
    std::printf("peak: force %.3f N, max Merkel SED %.1f Pa, max command %.2f %s%s\n", p.total_force_N, p.max_sed_Pa,
                p.max_command, result.display_unit.c_str(), SaturationNote(result).c_str());
  }
  PrintDisplayRendering(result);
  std::printf("timing: %.0f scans/s; latency median %.3f ms, p99 %.3f ms, max %.3f ms\n",
              result.wall_s > 0 ? result.counters.scans / result.wall_s : 0.0, result.latency.p50_ms,
              result.latency.p99_ms, result.latency.max_ms);
  std::printf("wrote %s/{summary.csv, peak_*.csv, bridge.lcmlog}\n", options.out_dir.c_str());
  if (signals.signal_number()) {
    std::printf("stopped by %s: display driven to zero, log closed\n", SignalName(signals.signal_number()));
    return signals.ExitCode(0);
  }
  if (!args.GetFlag("no-plots") && !result.rows.empty())
    RunPlotScript("plot_bridge.py", PlotBridgeArgs(options.out_dir, result));
  return 0;
}

}  // namespace
}  // namespace sedbridge::app

SEDBRIDGE_COMMAND(simulate, "simulate",
                  "simulated follower sensor -> CAN frames -> decoder -> bridge pipeline (offline, deterministic)",
                  &sedbridge::app::RunSimulateCommand);
