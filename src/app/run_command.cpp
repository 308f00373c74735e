// sedbridge run: the live bridge. SocketCAN -> scans -> FE -> SED -> display -> LCM.

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <thread>

#include "app/arg_parser.h"
#include "app/command.h"
#include "app/lcm_url.h"
#include "app/stop_signals.h"
#include "bridge/bridge_config.h"
#include "bridge/fingers.h"
#include "bridge/display_requests.h"
#include "bridge/live_bridge.h"
#include "bridge/live_hand_bridge.h"
#include "bridge/make_fe_step.h"
#include "bridge/replay.h"
#include "bridge/scene_fe_step.h"
#include "common/resource_path.h"
#include "display/display_profile.h"
#include "sensors/candump_log.h"
#include "sensors/multi_socketcan_source.h"
#include "sensors/socketcan_source.h"

namespace sedbridge::app {
namespace {

using namespace sedbridge::bridge;

// --duration-s: a thread that asks the signals to stop after S seconds (joined by the caller).
std::thread StartDurationTimer(const ArgParser& args, StopSignals& signals) {
  if (!args.Has("duration-s")) return {};
  const double s = args.GetDouble("duration-s");
  return std::thread([s, &signals] {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(s);
    while (!signals.flag().load() && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    signals.RequestStop();
  });
}

void WarnUnsigned(const lcm_io::LcmSettings& lcm) {
  if (lcm.auth_key_file.empty() && lcm.url.rfind("memq://", 0) != 0)
    std::fprintf(stderr,
                 "run: WARNING: DISPLAY_COMMAND is unsigned (no lcm.auth_key_file): a display driver that requires\n"
                 "     authentication (the default of sedbridge-display-driver) will ignore it; anyone on the LCM\n"
                 "     network could command the display. See display/README.md, \"Threat model\".\n");
}

// A hand (`fingers:`): one receiver over every bus the fingers name (a CAN_RAW socket a bus,
// polled together: sensors/multi_socketcan_source.h) or a `candump -l any` log, frames routed
// to each finger; a solver thread and a display per finger (bridge/live_hand_bridge.h).
// --log-input LOG: the recording played at its own pace, stamped as if it arrived now.
std::unique_ptr<sensors::FrameSource> RecordingAsLive(const std::string& log) {
  sensors::PlaybackOptions playback;
  playback.speed = 1.0;
  playback.restamp = true;
  return std::make_unique<sensors::CandumpLogSource>(config::ResolveResource(log), playback);
}

void RequireSocketCan() {
  std::string why;
  if (!sensors::SocketCanSource::KernelHasCan(&why))
    throw std::runtime_error("no SocketCAN here: " + why + " (try --log-input LOG to run on a recording)");
}

int RunHand(const ArgParser& args, BridgeConfig config, const LcmUrlChoice& lcm_url, StopSignals& signals) {
  if (args.Has("interface"))
    throw UsageError("--interface is one finger's: a config with 'fingers:' names each finger's bus");
  std::vector<HandFinger> fingers;
  for (Finger& f : FingersOf(config)) {
    f.config.lcm.url = lcm_url.url;
    // lcm.log: a log a finger (PATH_<name>.EXT), as its channels are its own.
    if (!f.config.lcm.log_path.empty()) {
      const std::filesystem::path log(f.config.lcm.log_path);
      f.config.lcm.log_path =
          (log.parent_path() / (log.stem().string() + "_" + f.name + log.extension().string())).string();
    }
    std::printf("finger %s: sensor %s (id offset %d) on %s, model %s/%s, display %s\n", f.name.c_str(),
                f.config.sensor_profile.c_str(), f.config.can_id_offset, f.config.can_interface.c_str(),
                f.config.model.c_str(), f.config.preset.c_str(), f.config.display_profile.c_str());
    fingers.push_back({f.name, f.config, LoadFingerSensorProfile(f.config),
                       display::LoadNamedDisplayProfile(f.config.display_profile), nullptr});
  }
  std::fflush(stdout);
  // Every leader model before any bus is opened or display driven: one that fails stops here.
  LeaderModelCache leaders;
  BuildHandFeSteps(fingers, false, &leaders);
  std::printf("leader models (fe.step contact): %d loaded; fingers reusing one already loaded: %d; pressure-map "
              "precomputes reused: %d\n",
              leaders.models_loaded(), leaders.models_shared(), leaders.fallbacks_shared());

  std::unique_ptr<sensors::FrameSource> source;
  sensors::MultiSocketCanSource* buses = nullptr;
  LiveOptions live;
  if (auto log = args.GetOptional("log-input")) {
    source = RecordingAsLive(*log);
  } else {
    RequireSocketCan();
    // One socket a bus, its kernel filters the union of its fingers' ids.
    std::map<std::string, sensors::SocketCanOptions> by_bus;
    for (const HandFinger& f : fingers) {
      const sensors::SocketCanOptions o = sensors::OptionsForProfile(f.profile, f.config.can_interface);
      auto [it, fresh] = by_bus.emplace(o.interface, o);
      if (!fresh) {
        it->second.fd_frames = it->second.fd_frames || o.fd_frames;
        it->second.filters.insert(it->second.filters.end(), o.filters.begin(), o.filters.end());
      }
    }
    std::vector<sensors::SocketCanOptions> options;
    for (auto& [name, o] : by_bus) options.push_back(o);
    auto open = sensors::MultiSocketCanSource::Open(options);
    buses = open.get();
    source = std::move(open);
  }
  auto send_all = [&](bool start) {
    if (!buses) return;
    for (const HandFinger& f : fingers)
      for (const sensors::Frame& frame : start ? f.profile.start_frames : f.profile.stop_frames)
        buses->Send(f.config.can_interface, frame);
  };
  send_all(true);
  std::printf("run: %s, %zu fingers, LCM %s (from %s)\n", source->Describe().c_str(), fingers.size(),
              lcm_url.url.c_str(), lcm_url.source.c_str());
  WarnUnsigned(config.lcm);

  // Each finger's display rendering and pipeline; one that fails to build leaves the ones
  // built (their destructors zero them) and stops the start-up.
  std::vector<std::unique_ptr<DisplayRequests>> requests;
  std::vector<std::unique_ptr<BridgePipeline>> pipelines;
  std::vector<LiveFinger> live_fingers;
  InverseRenderingCache renderings;  // fingers with the same leader model and display share one
  for (HandFinger& f : fingers) {
    requests.push_back(std::make_unique<DisplayRequests>(
        MakeDisplayRequests(f.config, f.display_profile, f.fe->merkel_rest_pad_mm(), [](const std::string& line) {
          std::printf("%s\n", line.c_str());
          std::fflush(stdout);
        }, &renderings)));
    pipelines.push_back(std::make_unique<BridgePipeline>(f.config, f.profile, f.display_profile, std::move(f.fe),
                                                         f.config.lcm, BridgePipeline::WallClock{},
                                                         requests.back()->source()));
    std::printf("finger %s: %s\n%s\n", f.name.c_str(), pipelines.back()->fe().Describe().c_str(),
                requests.back()->Describe().c_str());
    live_fingers.push_back({f.name, f.config.can_interface, &f.profile, pipelines.back().get(),
                            static_cast<int64_t>(1e6 / f.config.tick_Hz), f.config.tare_scans});
  }
  std::function<sensors::FrameSourceStats(const std::string&)> bus_stats;
  if (buses) bus_stats = [buses](const std::string& bus) { return buses->Stats(bus); };
  LiveHandBridge bridge(*source, live_fingers, live, bus_stats);

  std::thread timer = StartDurationTimer(args, signals);
  LiveHandResult result;
  try {
    result = bridge.Run(signals.flag());  // zeroes every display on every way out
  } catch (...) {
    signals.RequestStop();
    if (timer.joinable()) timer.join();
    send_all(false);
    throw;
  }
  signals.RequestStop();
  if (timer.joinable()) timer.join();

  std::printf("\nstopped (%s): %lld frames\n",
              signals.signal_number() ? SignalName(signals.signal_number())
              : result.stopped_by_request ? "duration"
                                          : "source done",
              static_cast<long long>(result.frames));
  for (size_t i = 0; i < fingers.size(); ++i) {
    const LiveResult& r = result.fingers[i];
    const BridgePipeline& p = *pipelines[i];
    const LatencySummary lat = p.latency().Run();
    std::printf("\n== finger %s (%s) ==\nscans received %lld, processed %lld, dropped (newest wins) %lld, rejected "
                "%lld; ticks %lld\n",
                fingers[i].name.c_str(), fingers[i].config.can_interface.c_str(),
                static_cast<long long>(r.scans_received), static_cast<long long>(r.scans_processed),
                static_cast<long long>(r.scans_dropped), static_cast<long long>(p.counters().scans_rejected),
                static_cast<long long>(r.ticks));
    std::printf("latency (receive -> publish): median %.3f ms, p99 %.3f ms, max %.3f ms\n", lat.p50_ms, lat.p99_ms,
                lat.max_ms);
    std::printf("bad frames:\n%s", sensors::FormatCounters(bridge.assembler(i).counters()).c_str());
    std::printf("display driven to zero; LCM messages %lld (%lld errors)\n",
                static_cast<long long>(pipelines[i]->display().publisher().published()),
                static_cast<long long>(pipelines[i]->display().publisher().publish_errors()));
  }
  for (const auto& [bus, count] : result.unclaimed_frames)
    std::printf("frames no finger claims on %s: %lld\n", bus.c_str(), static_cast<long long>(count));
  send_all(false);
  return signals.ExitCode(0);
}

int RunLiveCommand(int argc, char** argv) {
  ArgParser args("sedbridge run",
                 "The live bridge: a receiver thread reads the sensor's CAN frames (SocketCAN) into\n"
                 "a newest-scan slot; this thread takes the newest scan, steps the FE model and\n"
                 "publishes the display command on LCM (older scans are dropped and counted).\n"
                 "SIGINT (Ctrl-C), SIGTERM, SIGHUP or SIGQUIT stops cleanly (exit status 128 + signal); the\n"
                 "display is driven to zero and the LCM log closed on every exit and on any fault. Status on BRIDGE_STATUS; a summary is printed at exit.\n"
                 "A hand (a config with fingers:): one receiver reads every bus the fingers name (a CAN_RAW socket\n"
                 "a bus, polled together) or a candump -l any log, routes frames by bus and CAN id to each finger,\n"
                 "and each finger has its own solver thread and display (channels <CHANNEL>_<FINGER>): a finger\n"
                 "whose sensor goes silent or bus-off ramps its own display to zero while the others go on;\n"
                 "every exit zeroes every display.");
  args.Option("config", "BRIDGE.yaml", "bridge config", "config/bridge/default.yaml")
      .Option("interface", "NAME", "CAN interface (overrides sensor.interface; one finger only)")
      .Option("lcm-url", "URL", LcmUrlHelp("the config's lcm.url (udpm, ttl=0: this host only)"))
      .Option("log-input", "LOG", "instead of SocketCAN, play a candump log at recorded speed (restamped)")
      .Option("duration-s", "S", "stop after S seconds (default: until Ctrl-C)")
      .Option("threads", "N", "OpenMP threads for the FE step", "1")
      .Epilog("example:\n  sedbridge run --config config/bridge/default.yaml --interface can0\n"
              "  lcm-logger -c 'DISPLAY_COMMAND|BRIDGE_STATUS' out/run.lcmlog   # record in another shell\n"
              "  sedbridge run --interface can0 --lcm-url 'udpm://239.255.76.67:7667?ttl=1'  # leader on another host\n"
              "  sedbridge run --config config/bridge/example_hand.yaml   # a hand: can0 and can1 as its fingers name\n"
              "  sedbridge run --config config/bridge/example_hand.yaml --log-input config/bridge/example_hand.log\n"
              "LCM URL: --lcm-url, else $LCM_DEFAULT_URL, else the config's lcm.url (docs/two-host.md)");
  if (!args.Parse(argc, argv)) return 0;
  StopSignals signals;  // from here on, a signal stops through the normal exit (zero, log closed)

  SetFeThreads(static_cast<int>(args.GetInt("threads")));
  BridgeConfig config = LoadBridgeConfig(config::ResolveResource(args.Get("config")));
  const LcmUrlChoice lcm_url = ChooseLcmUrl(args.GetOptional("lcm-url"), config.lcm.url, "config lcm.url");
  if (!config.fingers.empty()) return RunHand(args, config, lcm_url, signals);
  config.lcm.url = lcm_url.url;
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile(config.sensor_profile);
  const std::string interface = args.GetOptional("interface").value_or(config.can_interface);

  std::unique_ptr<sensors::FrameSource> source;
  LiveOptions live;
  live.tick_period_us = static_cast<int64_t>(1e6 / config.tick_Hz);
  if (auto log = args.GetOptional("log-input")) {
    source = RecordingAsLive(*log);
  } else {
    RequireSocketCan();
    auto can = std::make_unique<sensors::SocketCanSource>(sensors::OptionsForProfile(profile, interface));
    for (const sensors::Frame& f : profile.start_frames) can->Send(f);
    source = std::move(can);
  }

  std::printf("run: %s, sensor %s -> model %s/%s -> display %s, LCM %s (from %s)\n", source->Describe().c_str(),
              profile.name.c_str(), config.model.c_str(), config.preset.c_str(), config.display_profile.c_str(),
              config.lcm.url.c_str(), lcm_url.source.c_str());
  WarnUnsigned(config.lcm);
  std::unique_ptr<FeStep> fe = MakeFeStep(config, profile);
  display::DisplayProfile display_profile = display::LoadNamedDisplayProfile(config.display_profile);
  const DisplayRequests requests = MakeDisplayRequests(config, display_profile, fe->merkel_rest_pad_mm(),
                                                       [](const std::string& line) {
                                                         std::printf("%s\n", line.c_str());
                                                         std::fflush(stdout);
                                                       });
  BridgePipeline pipeline(config, profile, std::move(display_profile), std::move(fe), config.lcm, {},
                          requests.source());
  if (auto inverse = requests.inverse)
    pipeline.SetPredictedSed([inverse](Eigen::VectorXd* sed, std::vector<double>* u) { inverse->PredictedSed(sed, u); });
  std::printf("%s\n%s\n", pipeline.fe().Describe().c_str(), requests.Describe().c_str());
  sensors::AssemblerOptions assembler_options;
  assembler_options.tare_scans = config.tare_scans;
  // A log may hold several buses; a SocketCAN socket is bound to `interface` already.
  if (args.Has("log-input")) assembler_options.interface = interface;
  sensors::ScanAssembler assembler(profile, assembler_options);

  std::thread timer = StartDurationTimer(args, signals);
  LiveBridge bridge(*source, assembler, pipeline, live);
  LiveResult result;
  try {
    result = bridge.Run(signals.flag());  // shuts the display down on every way out
  } catch (...) {
    signals.RequestStop();
    if (timer.joinable()) timer.join();
    throw;
  }
  signals.RequestStop();
  if (timer.joinable()) timer.join();

  const LatencySummary lat = pipeline.latency().Run();
  const PipelineCounters& c = pipeline.counters();
  std::printf("\nstopped (%s): scans received %lld, processed %lld, dropped (newest wins) %lld, rejected %lld; "
              "ticks %lld\n",
              signals.signal_number() ? SignalName(signals.signal_number())
              : result.stopped_by_request ? "duration"
                                          : "source done",
              static_cast<long long>(result.scans_received), static_cast<long long>(result.scans_processed),
              static_cast<long long>(result.scans_dropped), static_cast<long long>(c.scans_rejected),
              static_cast<long long>(result.ticks));
  std::printf("latency (receive -> publish): median %.3f ms, p99 %.3f ms, max %.3f ms\n", lat.p50_ms, lat.p99_ms,
              lat.max_ms);
  std::printf("stages (median ms): %s\n", FormatStageTimes(pipeline.RunStageMedians_ms()).c_str());
  if (requests.inverse) {
    const LatencySummary r = requests.inverse->render_times().Run(), cpu = requests.inverse->render_cpu_times().Run();
    std::printf("inverse renderer a scan (inside the limiter stage): wall median %.3f ms, p99 %.3f ms, max %.3f ms; "
                "CPU median %.3f ms, p99 %.3f ms\n",
                r.p50_ms, r.p99_ms, r.max_ms, cpu.p50_ms, cpu.p99_ms);
  }
  if (c.scans_rejected > 0) std::printf("rejected scans by reason: %s\n", FormatRejectCounters(c.rejected_by_reason).c_str());
  std::printf("bad frames:\n%s", sensors::FormatCounters(assembler.counters()).c_str());
  std::printf("display driven to zero; LCM messages %lld (%lld errors)\n",
              static_cast<long long>(pipeline.display().publisher().published()),
              static_cast<long long>(pipeline.display().publisher().publish_errors()));
  if (auto* can = dynamic_cast<sensors::SocketCanSource*>(source.get()))
    for (const sensors::Frame& f : profile.stop_frames) can->Send(f);
  return signals.ExitCode(0);
}

}  // namespace
}  // namespace sedbridge::app

SEDBRIDGE_COMMAND(run, "run", "the live bridge: SocketCAN -> FE -> SED -> display over LCM (Ctrl-C stops, display to zero)",
                  &sedbridge::app::RunLiveCommand);
