// sedbridge run: the live bridge. SocketCAN -> scans -> FE -> SED -> display -> LCM.

#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

#include "app/arg_parser.h"
#include "app/command.h"
#include "app/lcm_url.h"
#include "app/stop_signals.h"
#include "bridge/bridge_config.h"
#include "bridge/fingers.h"
#include "bridge/display_requests.h"
#include "bridge/live_bridge.h"
#include "bridge/make_fe_step.h"
#include "bridge/scene_fe_step.h"
#include "common/resource_path.h"
#include "display/display_profile.h"
#include "sensors/candump_log.h"
#include "sensors/socketcan_source.h"

namespace sedbridge::app {
namespace {

using namespace sedbridge::bridge;

int RunLiveCommand(int argc, char** argv) {
  ArgParser args("sedbridge run",
                 "The live bridge: a receiver thread reads the sensor's CAN frames (SocketCAN) into\n"
                 "a newest-scan slot; this thread takes the newest scan, steps the FE model and\n"
                 "publishes the display command on LCM (older scans are dropped and counted).\n"
                 "SIGINT (Ctrl-C), SIGTERM, SIGHUP or SIGQUIT stops cleanly (exit status 128 + signal); the\n"
                 "display is driven to zero and the LCM log closed on every exit and on any fault. Status on BRIDGE_STATUS; a summary is printed at exit.");
  args.Option("config", "BRIDGE.yaml", "bridge config", "config/bridge/default.yaml")
      .Option("interface", "NAME", "CAN interface (overrides sensor.interface)")
      .Option("lcm-url", "URL", LcmUrlHelp("the config's lcm.url (udpm, ttl=0: this host only)"))
      .Option("log-input", "LOG", "instead of SocketCAN, play a candump log at recorded speed (restamped)")
      .Option("duration-s", "S", "stop after S seconds (default: until Ctrl-C)")
      .Option("threads", "N", "OpenMP threads for the FE step", "1")
      .Epilog("example:\n  sedbridge run --config config/bridge/default.yaml --interface can0\n"
              "  lcm-logger -c 'DISPLAY_COMMAND|BRIDGE_STATUS' out/run.lcmlog   # record in another shell\n"
              "  sedbridge run --interface can0 --lcm-url 'udpm://239.255.76.67:7667?ttl=1'  # leader on another host\n"
              "LCM URL: --lcm-url, else $LCM_DEFAULT_URL, else the config's lcm.url (docs/two-host.md)");
  if (!args.Parse(argc, argv)) return 0;
  StopSignals signals;  // from here on, a signal stops through the normal exit (zero, log closed)

  SetFeThreads(static_cast<int>(args.GetInt("threads")));
  BridgeConfig config = LoadBridgeConfig(config::ResolveResource(args.Get("config")));
  RequireOneFinger(config, "run");
  const LcmUrlChoice lcm_url = ChooseLcmUrl(args.GetOptional("lcm-url"), config.lcm.url, "config lcm.url");
  config.lcm.url = lcm_url.url;
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile(config.sensor_profile);
  const std::string interface = args.GetOptional("interface").value_or(config.can_interface);

  std::unique_ptr<sensors::FrameSource> source;
  LiveOptions live;
  live.tick_period_us = static_cast<int64_t>(1e6 / config.tick_Hz);
  if (auto log = args.GetOptional("log-input")) {
    sensors::PlaybackOptions playback;
    playback.speed = 1.0;
    playback.restamp = true;
    source = std::make_unique<sensors::CandumpLogSource>(config::ResolveResource(*log), playback);
  } else {
    std::string why;
    if (!sensors::SocketCanSource::KernelHasCan(&why))
      throw std::runtime_error("no SocketCAN here: " + why + " (try --log-input LOG to run on a recording)");
    auto can = std::make_unique<sensors::SocketCanSource>(sensors::OptionsForProfile(profile, interface));
    for (const sensors::Frame& f : profile.start_frames) can->Send(f);
    source = std::move(can);
  }

  std::printf("run: %s, sensor %s -> model %s/%s -> display %s, LCM %s (from %s)\n", source->Describe().c_str(),
              profile.name.c_str(), config.model.c_str(), config.preset.c_str(), config.display_profile.c_str(),
              config.lcm.url.c_str(), lcm_url.source.c_str());
  if (config.lcm.auth_key_file.empty() && config.lcm.url.rfind("memq://", 0) != 0)
    std::fprintf(stderr,
                 "run: WARNING: DISPLAY_COMMAND is unsigned (no lcm.auth_key_file): a display driver that requires\n"
                 "     authentication (the default of sedbridge-display-driver) will ignore it; anyone on the LCM\n"
                 "     network could command the display. See display/README.md, \"Threat model\".\n");
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

  std::thread timer;
  if (args.Has("duration-s")) {
    const double s = args.GetDouble("duration-s");
    timer = std::thread([s, &signals] {
      const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(s);
      while (!signals.flag().load() && std::chrono::steady_clock::now() < end)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      signals.RequestStop();
    });
  }
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
