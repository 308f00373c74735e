// `sedbridge view`: a small web server that shows the bridge in a browser page: the taxels and
// the contact the bridge read, the fingertip's Merkel SED in 3-D, the display's actuators and
// the timelines, from an LCM log (play, pause, seek, speed) or live from any LCM URL.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/arg_parser.h"
#include "app/command.h"
#include "app/lcm_url.h"
#include "app/stop_signals.h"
#include "common/resource_path.h"
#include "lcm/lcm_channels.h"
#include "view/frame_json.h"
#include "view/live_source.h"
#include "view/log_player.h"
#include "view/view_server.h"

namespace sedbridge::app {
namespace {

using namespace sedbridge::view;

// The page's files: --web-dir, else an installed tree's (share/sedbridge/view_web, found as
// config/ is), else the build tree's copy.
std::string WebDir(const ArgParser& args) {
  if (auto dir = args.GetOptional("web-dir")) return *dir;
  namespace fs = std::filesystem;
  const std::string installed = config::ResolveResource("view_web");
  if (fs::exists(fs::path(installed) / "index.html")) return installed;
#ifdef SEDBRIDGE_VIEW_WEB_DIR
  return SEDBRIDGE_VIEW_WEB_DIR;
#else
  return installed;
#endif
}

// The logs --log names: the file, or every *.lcmlog under a folder (a hand's replay writes
// one a finger: out/hand/<finger>/bridge.lcmlog), in name order.
std::vector<std::string> LogFiles(const std::string& path) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(path)) return {path};
  std::vector<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(path))
    if (entry.is_regular_file() && entry.path().extension() == ".lcmlog") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw UsageError("--log " + path + ": a folder without any *.lcmlog");
  return files;
}

bool IsLoopback(const std::string& host) {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

// "play", "pause", "seek S", "speed X" -> the player; "" when done, else why not.
std::string Control(LogPlayer* player, ViewState* state, const std::string& body) {
  std::istringstream in(body);
  std::string verb;
  double value = NAN;
  in >> verb;
  if (verb == "play") {
    if (player->position_s() >= player->duration_s()) player->Seek(0, state);
    player->SetPlaying(true);
  } else if (verb == "pause") {
    player->SetPlaying(false);
  } else if (verb == "seek" && (in >> value) && std::isfinite(value)) {
    player->Seek(value, state);
  } else if (verb == "speed" && (in >> value) && value > 0) {
    player->SetSpeed(value);
  } else {
    return "expected 'play', 'pause', 'seek SECONDS' or 'speed FACTOR'";
  }
  return "";
}

void DeclareOptions(ArgParser* args) {
  args->Option("log", "PATH", "play this LCM event log instead of listening live; a folder: every *.lcmlog in it, as one (a hand's replay --out)")
      .Option("lcm-url", "URL", std::string("live: LCM URL to listen on; default: $LCM_DEFAULT_URL if set, else ") +
                                    lcm_io::kDefaultLcmUrl)
      .Option("bind", "ADDR", "address to serve on; anything but loopback shows the page to the network", "127.0.0.1")
      .Option("port", "N", "TCP port; 0 = any free port", "8053")
      .Option("port-file", "FILE", "write the port served on to FILE (for scripts with --port 0)")
      .Option("web-dir", "DIR", "the page's files (default: the install's share/sedbridge/view_web, else the build's)")
      .Option("model", "NAME", "fingertip model for the 3-D panel (default: the models of the log's SED fields, live: B)")
      .Option("sensor", "NAME", "sensor profile for the taxel layout (default: the scans' sensor_id)")
      .Option("display", "NAME", "display profile for the actuator layout (default: the commands' display_id)")
      .Option("sed-scale-Pa", "PA", "top of the fixed SED colour scale [Pa] (default: log: its largest SED; live: 1000)")
      .Option("fps", "N", "frames per second sent to the page (at most)", "30")
      .Option("speed", "X", "log: playback speed", "1")
      .Option("start-s", "S", "log: start at S seconds into the log", "0")
      .Flag("paused", "log: start paused (the page's play button starts it)")
      .Option("duration-s", "S", "stop after S seconds; 0 = until Ctrl-C", "0")
      .Option("tactile-channel", "NAME", "LCM channel (a hand's fingers: NAME_<FINGER>, found on the bus)", "TACTILE_SCAN")
      .Option("contact-channel", "NAME", "LCM channel", "CONTACT_ESTIMATE")
      .Option("sed-channel", "NAME", "LCM channel", "FINGERTIP_SED")
      .Option("command-channel", "NAME", "LCM channel", "DISPLAY_COMMAND")
      .Option("sa1-channel", "NAME", "LCM channel", "SA1_RATE_ESTIMATE")
      .Option("status-channel", "NAME", "LCM channel", "BRIDGE_STATUS")
      .Option("rendering-channel", "NAME", "LCM channel (target and delivered SED, inverse rendering)", "DISPLAY_RENDERING")
      .Epilog(
          "examples:\n"
          "  sedbridge view --log out/replay/bridge.lcmlog      # then open http://127.0.0.1:8053/\n"
          "  sedbridge view --log out/hand                      # a hand's replay: one log a finger\n"
          "  sedbridge view --lcm-url 'udpm://239.255.76.67:7667?ttl=0'\n"
          "The page's 3-D and plots come from three.js and uPlot, installed by tools/setup.sh\n"
          "(npm ci in tools/view-web) and copied into the build; nothing is fetched at run time.\n"
          "exit status: 0 ok, 1 error, 2 usage");
}

// What the frame loop and the page's control requests share.
struct Session {
  std::mutex mu;  // guards state, player and dirty: the frame loop and the control requests
  ViewState state;
  std::unique_ptr<LogPlayer> player;
  std::unique_ptr<LiveSource> live;
  PlaybackInfo playback;
  FrameStyle style;
  bool dirty = true;
  explicit Session(const lcm_io::LcmChannels& ch) : state(ch) {}
};

// The frame loop: moves the log (or takes the bus's messages), and at most `fps` times a
// second makes a frame when something changed, until a signal or `duration_s`. Returns the
// number of frames made.
int64_t RunFrames(Session& s, ViewLayouts& layouts, const std::vector<SedMesh>& meshes, FrameHub& hub, double fps,
                  double duration_s, const StopSignals& signals) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto period = std::chrono::duration<double>(1.0 / fps);
  auto last = start;
  uint64_t sent_version = ~uint64_t(0);
  int64_t frames = 0;
  std::map<std::string, SedVertexMatch> matches;  // per finger
  while (!signals.flag().load()) {
    if (duration_s > 0 && std::chrono::duration<double>(Clock::now() - start).count() >= duration_s) break;
    const auto next = last + std::chrono::duration_cast<Clock::duration>(period);
    if (s.live) {
      const int wait_ms = int(std::chrono::duration<double, std::milli>(next - Clock::now()).count());
      s.live->Handle(std::max(0, wait_ms));
      if (Clock::now() < next) continue;  // more messages before the next frame
    } else {
      std::this_thread::sleep_until(next);
    }
    const auto now = Clock::now();
    std::string frame;
    {
      std::lock_guard<std::mutex> lock(s.mu);
      PlaybackInfo& p = s.playback;
      if (s.player) {
        const bool was_playing = s.player->playing();
        s.player->Advance(std::chrono::duration<double>(now - last).count(), &s.state);
        if (was_playing) s.dirty = true;
        p.position_s = s.player->position_s();
        p.duration_s = s.player->duration_s();
        p.playing = s.player->playing();
        p.speed = s.player->speed();
      } else {
        p.position_s = s.state.last_utime > 0 ? (s.state.last_utime - s.state.first_utime) * 1e-6 : 0;
        p.duration_s = p.position_s;
      }
      if (s.dirty || s.state.version != sent_version) {
        frame = FrameJson(s.state, layouts, meshes, matches, p, s.style);
        sent_version = s.state.version;
        s.dirty = false;
      }
    }
    last = now;
    if (!frame.empty()) {
      hub.Publish(std::move(frame));
      ++frames;
    }
  }
  return frames;
}

int RunView(int argc, char** argv) {
  ArgParser args("sedbridge view",
                 "A web page that shows the bridge at work: the taxel grid (normal pressure as\n"
                 "colour, a three-axis sensor's shear as an arrow a taxel) with the contact the\n"
                 "bridge reconstructed (its total shear, residual and flag), the leader's skin in\n"
                 "3-D coloured by the Merkel-layer SED beneath it on a fixed scale, the display's\n"
                 "actuators with the target | delivered SED (DISPLAY_RENDERING, inverse\n"
                 "rendering) and timelines of force, peak SED and per-scan latency; one panel per\n"
                 "finger for a hand (channels NAME_<FINGER>).\n"
                 "From an LCM log (play, pause, seek, speed on the page) or live\n"
                 "from LCM. Read-only: the view subscribes, it never publishes.");
  DeclareOptions(&args);
  if (!args.Parse(argc, argv)) return 0;

  lcm_io::LcmChannels ch;
  ch.tactile_scan = args.Get("tactile-channel");
  ch.contact = args.Get("contact-channel");
  ch.sed = args.Get("sed-channel");
  ch.command = args.Get("command-channel");
  ch.sa1_rate = args.Get("sa1-channel");
  ch.status = args.Get("status-channel");
  ch.rendering = args.Get("rendering-channel");
  try {
    ch.Validate();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  const double fps = args.GetDouble("fps");
  if (!(fps > 0 && fps <= 120)) throw UsageError("--fps must be in (0, 120]");
  const long port = args.GetInt("port");
  if (port < 0 || port > 65535) throw UsageError("--port must be in [0, 65535]");
  const std::string bind = args.Get("bind");
  if (!IsLoopback(bind))
    std::fprintf(stderr,
                 "view: WARNING: serving on %s: anyone who can reach this address sees the bridge's data "
                 "(the page is read-only, but it is not authenticated)\n",
                 bind.c_str());

  Session session(ch);
  const ViewState& classifier = session.state;
  const auto is_ours = [&classifier](const std::string& channel) {
    ChannelKind kind;
    std::string finger;
    return classifier.Classify(channel, &kind, &finger);
  };
  const auto is_sed = [&classifier](const std::string& channel) {
    ChannelKind kind;
    std::string finger;
    return classifier.Classify(channel, &kind, &finger) && kind == ChannelKind::kSed;
  };
  const auto log = args.GetOptional("log");
  std::vector<std::string> models;
  if (auto model = args.GetOptional("model")) models = {*model};
  FrameStyle& style = session.style;
  if (log) {
    session.player = std::make_unique<LogPlayer>(LogFiles(*log), is_ours);
    LogPlayer& player = *session.player;
    player.SetSpeed(args.GetDouble("speed"));
    player.Seek(args.GetDouble("start-s"), &session.state);
    player.SetPlaying(!args.GetFlag("paused"));
    style.sed_scale_Pa = player.LargestSed_Pa(is_sed);
    if (models.empty()) models = player.SedModels(is_sed);
    session.playback.source = *log;
  } else {
    const std::string url = ChooseLcmUrl(args.GetOptional("lcm-url"), lcm_io::kDefaultLcmUrl, "default").url;
    session.live =
        std::make_unique<LiveSource>(url, session.state.SubscriptionPatterns(), &session.state, &session.mu);
    session.playback.live = true;
    session.playback.source = url;
    style.sed_scale_Pa = 1000;
  }
  if (args.Has("sed-scale-Pa")) style.sed_scale_Pa = args.GetDouble("sed-scale-Pa");
  if (!(style.sed_scale_Pa > 0)) style.sed_scale_Pa = 1000;
  if (models.empty()) models = {"B"};
  std::vector<SedMesh> meshes;
  std::string model_names;
  for (const std::string& model : models) {
    meshes.push_back(LoadSedMesh(model));
    model_names += (model_names.empty() ? "" : ", ") + meshes.back().model_id;
    if (!meshes.back().error.empty())
      std::fprintf(stderr, "view: no mesh for model '%s' (%s); SED drawn as points\n", model.c_str(),
                   meshes.back().error.c_str());
  }
  const std::string mesh_json = MeshJson(meshes, style);

  FrameHub hub;
  ViewLayouts layouts(args.GetOptional("sensor").value_or(""), args.GetOptional("display").value_or(""));
  ViewServerOptions server_options;
  server_options.bind = bind;
  server_options.port = int(port);
  server_options.web_dir = WebDir(args);
  if (!std::filesystem::exists(std::filesystem::path(server_options.web_dir) / "index.html"))
    throw std::runtime_error("no page in '" + server_options.web_dir + "' (build the target sedbridge_view_web, or --web-dir)");
  ViewServer server(
      server_options, &hub, [&] { return mesh_json; },
      [&](const std::string& body) -> std::string {
        if (!session.player) return "live view: there is no playback to control";
        std::lock_guard<std::mutex> lock(session.mu);
        session.dirty = true;
        return Control(session.player.get(), &session.state, body);
      });
  server.Start();
  if (auto file = args.GetOptional("port-file")) std::ofstream(*file) << server.port() << "\n";
  std::fprintf(stderr, "view: serving http://%s:%d/ (%s %s, model %s, SED scale %.4g Pa); Ctrl-C to stop\n",
               bind.find(':') != std::string::npos ? ("[" + bind + "]").c_str() : bind.c_str(), server.port(),
               log ? "log" : "live", session.playback.source.c_str(), model_names.c_str(), style.sed_scale_Pa);

  StopSignals signals;
  const int64_t frames = RunFrames(session, layouts, meshes, hub, fps, args.GetDouble("duration-s"), signals);
  server.Stop();
  std::fprintf(stderr, "view: %lld frames made, %lld sent to %lld page streams; %lld events, %lld malformed rejected\n",
               static_cast<long long>(frames), static_cast<long long>(hub.frames_sent.load()),
               static_cast<long long>(hub.clients_total.load()), static_cast<long long>(session.state.events),
               static_cast<long long>(session.state.rejected));
  return signals.ExitCode(0);
}

}  // namespace
}  // namespace sedbridge::app

SEDBRIDGE_COMMAND(view, "view", "serve a web page that shows the bridge live or from an LCM log", &sedbridge::app::RunView);
