// `sedbridge display-view`: shows what the leader's finger would feel — the display command as
// a live terminal heatmap (LCM live or from a log), or PNG frames / a GIF from a log.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "app/arg_parser.h"
#include "app/command.h"
#include "app/lcm_url.h"
#include "app/plot_runner.h"
#include "common/config_error.h"
#include "common/resource_path.h"
#include "display/command_authenticator.h"
#include "display/display_profile.h"
#include "display/terminal_heatmap.h"
#include "lcm/display_command_message.h"
#include "lcm/display_log_frames.h"
#include "lcm/lcm_channels.h"
#include "lcm/lcm_safe_decode.h"
#include "lcm/merkel_sed_message.h"
#include "lcm/taxel_health_message.h"
#include "sedbridge/lcmt_bridge_status.hpp"
#include "sedbridge/lcmt_display_command.hpp"
#include "sedbridge/lcmt_merkel_sed.hpp"

namespace sedbridge::app {
namespace {

using namespace sedbridge::display;
using namespace sedbridge::lcm_io;

volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

// The actuator layout: from --profile, else from the command's display_id, else a single row.
class LayoutSource {
 public:
  explicit LayoutSource(std::string profile_path) : profile_path_(std::move(profile_path)) {
    if (!profile_path_.empty()) Load(profile_path_);
  }
  const ActuatorLayout& For(const DisplayCommand& c) {
    if (have_ && (fixed_ || c.display_id == id_) && layout_.x_mm.size() == c.value.size()) return layout_;
    if (!fixed_ && !c.display_id.empty() && c.display_id != tried_) {
      tried_ = c.display_id;
      try {
        Load("config/displays/" + c.display_id + ".yaml");
      } catch (const config::ConfigError& e) {
        std::fprintf(stderr, "display-view: no profile for '%s' (%s); showing a plain row\n",
                     c.display_id.c_str(), e.what());
      }
      if (have_ && layout_.x_mm.size() == c.value.size()) return layout_;
    }
    // Unknown display: one row, full scale from the values seen.
    fallback_.x_mm.clear();
    fallback_.y_mm.clear();
    for (std::size_t i = 0; i < c.value.size(); ++i) {
      fallback_.x_mm.push_back(static_cast<double>(i));
      fallback_.y_mm.push_back(0);
      if (std::isfinite(c.value[i])) fallback_.max = std::max(fallback_.max, c.value[i]);
    }
    fallback_.unit = c.unit;
    return fallback_;
  }
  std::string id() const { return id_; }

 private:
  void Load(const std::string& path) {
    const DisplayProfile p = LoadDisplayProfile(path);
    layout_ = {p.x_mm, p.y_mm, p.safety.max, p.unit};
    id_ = p.name;
    have_ = true;
    fixed_ = !profile_path_.empty();
  }
  std::string profile_path_, id_, tried_;
  ActuatorLayout layout_, fallback_;
  bool have_ = false, fixed_ = false;
};

struct LiveState {
  bool have_command = false, have_sed = false, new_command = false;
  DisplayCommand command;
  SedField sed;
  std::vector<int8_t> taxel_health;  ///< the latest BRIDGE_STATUS's
  int64_t commands = 0, fields = 0;
  int64_t rejected = 0;  ///< messages whose array counts their bytes cannot hold (or not decodable)
  // Raw subscriptions: lcm-cpp's typed subscribe would decode (and allocate from the count
  // field) before we could check; SafeDecode checks first.
  void OnCommand(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    lcmt_display_command m;
    // A signed command (lcm.auth_key_file) is payload || 32-byte HMAC tag. The viewer drives
    // nothing, so it shows the payload without checking the tag (it has no key).
    const bool plain = SafeDecode(rbuf->data, rbuf->data_size, &m);
    const bool with_tag = !plain && rbuf->data_size > CommandAuthenticator::kTagBytes &&
                          SafeDecode(rbuf->data, rbuf->data_size - CommandAuthenticator::kTagBytes, &m);
    if (!plain && !with_tag) {
      ++rejected;
      return;
    }
    command = FromLcm(m);
    have_command = new_command = true;
    ++commands;
  }
  void OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    lcmt_bridge_status m;
    if (!SafeDecode(rbuf->data, rbuf->data_size, &m)) {
      ++rejected;
      return;
    }
    taxel_health = m.taxel_health;
  }
  void OnSed(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    lcmt_merkel_sed m;
    if (!SafeDecode(rbuf->data, rbuf->data_size, &m)) {
      ++rejected;
      return;
    }
    sed = FromLcm(m);
    have_sed = true;
    ++fields;
  }
};

// The frame, and under it which taxels the bridge masks and why (its BRIDGE_STATUS, when
// one was seen): a masked taxel's readings do not drive the display.
void Show(const std::string& frame, const std::vector<int8_t>& taxel_health, bool clear) {
  if (clear) std::fputs("\033[H\033[2J", stdout);
  std::fputs(frame.c_str(), stdout);
  if (!taxel_health.empty()) std::printf("%s\n", DescribeTaxelHealth(taxel_health).c_str());
  std::fflush(stdout);
}

int RunLive(const ArgParser& args, const LcmChannels& ch, LayoutSource& layouts,
            const HeatmapStyle& style, bool clear) {
  auto flag = args.GetOptional("lcm-url");
  if (!flag) flag = args.GetOptional("url");
  const std::string url = ChooseLcmUrl(flag, kDefaultLcmUrl, "default").url;
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "display-view: cannot open LCM at '%s'\n", url.c_str());
    return 1;
  }
  LiveState state;
  lcm.subscribe(ch.command, &LiveState::OnCommand, &state);
  lcm.subscribe(ch.sed, &LiveState::OnSed, &state);
  lcm.subscribe(ch.status, &LiveState::OnStatus, &state);
  const double duration_s = args.GetDouble("duration-s");
  const double fps = std::max(0.5, args.GetDouble("fps"));
  const bool once = args.GetFlag("once");
  std::fprintf(stderr, "display-view: listening on %s, channels %s and %s (Ctrl-C to stop)\n",
               url.c_str(), ch.command.c_str(), ch.sed.c_str());
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto last_draw = start - std::chrono::hours(1);
  while (!g_stop) {
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (duration_s > 0 && elapsed >= duration_s) break;
    lcm.handleTimeout(20);
    if (state.new_command &&
        std::chrono::duration<double>(Clock::now() - last_draw).count() >= 1.0 / fps) {
      state.new_command = false;
      last_draw = Clock::now();
      Show(RenderHeatmap(layouts.For(state.command), state.command,
                         state.have_sed ? &state.sed : nullptr, style),
           state.taxel_health, clear);
      if (once) break;
    }
  }
  std::fprintf(stderr, "display-view: %lld commands, %lld SED fields received, %lld malformed rejected\n",
               static_cast<long long>(state.commands), static_cast<long long>(state.fields),
               static_cast<long long>(state.rejected));
  return state.have_command ? 0 : 3;
}

// The frame with the largest command (the first of equals): what --once shows from a log,
// rather than the last frame, which is the all-zero shutdown command.
std::size_t PeakFrame(const std::vector<DisplayFrame>& frames) {
  std::size_t best = frames.size() - 1;
  double best_value = -1;
  for (std::size_t i = 0; i < frames.size(); ++i)
    for (double v : frames[i].command.value)
      if (std::isfinite(v) && v > best_value) best_value = v, best = i;
  return best;
}

int RunLogTerminal(const ArgParser& args, const std::vector<DisplayFrame>& frames,
                   LayoutSource& layouts, HeatmapStyle style, bool clear) {
  const double speed = args.GetDouble("speed");
  const bool once = args.GetFlag("once");
  // One SED colour scale for the whole log (its largest finite SED), so a quiet frame looks quiet.
  if (style.sed_full_scale_Pa <= 0)
    for (const DisplayFrame& f : frames)
      if (f.has_sed)
        for (double e : f.sed.sed_Pa)
          if (std::isfinite(e)) style.sed_full_scale_Pa = std::max(style.sed_full_scale_Pa, e);
  if (once) {
    const std::size_t i = PeakFrame(frames);
    const DisplayFrame& f = frames[i];
    Show(RenderHeatmap(layouts.For(f.command), f.command, f.has_sed ? &f.sed : nullptr, style), f.taxel_health, clear);
    std::printf("frame %zu of %zu: the largest command in the log (t = %.3f s after the first frame)\n", i + 1,
                frames.size(), (f.log_utime - frames.front().log_utime) * 1e-6);
    return 0;
  }
  for (std::size_t i = 0; i < frames.size() && !g_stop; ++i) {
    const DisplayFrame& f = frames[i];
    if (i > 0 && speed > 0) {
      const double dt = (f.log_utime - frames[i - 1].log_utime) * 1e-6 / speed;
      if (dt > 0) std::this_thread::sleep_for(std::chrono::duration<double>(std::min(dt, 5.0)));
    }
    Show(RenderHeatmap(layouts.For(f.command), f.command, f.has_sed ? &f.sed : nullptr, style),
         f.taxel_health, clear);
  }
  return 0;
}

int RunLogImages(const ArgParser& args, const std::vector<DisplayFrame>& frames,
                 LayoutSource& layouts) {
  const std::string png_dir = args.GetOptional("png-dir").value_or("");
  const std::string animation = args.GetOptional("animation").value_or("");
  namespace fs = std::filesystem;
  const fs::path work = !png_dir.empty() ? fs::path(png_dir)
                                         : fs::temp_directory_path() /
                                               ("sedbridge_view_" + std::to_string(::getpid()));
  fs::create_directories(work);
  const std::string jsonl = (work / "frames.jsonl").string();
  const ActuatorLayout& layout = layouts.For(frames.front().command);
  WriteFramesJsonl(jsonl, layout, frames.front().command.display_id, frames);
  std::vector<std::string> script_args = {jsonl};
  if (!png_dir.empty()) script_args.insert(script_args.end(), {"--png-dir", png_dir});
  if (!animation.empty()) script_args.insert(script_args.end(), {"--animation", animation, "--fps", args.Get("fps")});
  std::string shown = args.Get("python") + " " + config::ResolveResource("tools/plot_display_frames.py");
  for (const auto& a : script_args) shown += " " + a;
  std::fprintf(stderr, "display-view: %zu frames -> %s\n", frames.size(), shown.c_str());
  const PlotResult plot = RunPythonScript("plot_display_frames.py", script_args, args.Get("python"));
  const int rc = plot.exit_code;
  if (!plot.ok && !plot.message.empty()) std::fprintf(stderr, "display-view: %s\n", plot.message.c_str());
  if (png_dir.empty()) fs::remove_all(work);
  if (rc != 0) {
    std::fprintf(stderr, "display-view: plotting failed (exit %d); the frames are in %s\n", rc,
                 jsonl.c_str());
    return 1;
  }
  return 0;
}

int RunDisplayView(int argc, char** argv) {
  ArgParser args("sedbridge display-view",
                 "Shows what the leader's finger would feel: the haptic display command as a\n"
                 "heatmap of the actuator array (tip at the top), with the Merkel-layer SED\n"
                 "field below it. Live from LCM, or from an LCM event log (--log), as a\n"
                 "terminal replay or as PNG frames / a GIF animation.");
  args.Option("log", "FILE", "read this LCM event log instead of listening live")
      .Option("lcm-url", "URL", "live: LCM URL to listen on; default: $LCM_DEFAULT_URL if set, else " +
                                    std::string(kDefaultLcmUrl))
      .Option("url", "URL", "same as --lcm-url (older name)")
      .Option("profile", "YAML", "display profile for the layout (default: from display_id)")
      .Option("command-channel", "NAME", "display command channel", "DISPLAY_COMMAND")
      .Option("sed-channel", "NAME", "Merkel SED channel", "FINGERTIP_SED")
      .Option("status-channel", "NAME", "bridge status channel: under each frame, the taxels the bridge masks and why",
              "BRIDGE_STATUS")
      .Option("fps", "N", "frames per second shown / sampled from a log", "10")
      .Option("speed", "X", "log replay speed in the terminal; 0 = no waiting", "1")
      .Option("duration-s", "S", "live: stop after S seconds; 0 = until Ctrl-C", "0")
      .Option("max-frames", "N", "log: at most N frames (the last one is always kept)", "2000")
      .Option("png-dir", "DIR", "log: write DIR/frame_00000.png ... (and DIR/frames.jsonl)")
      .Option("animation", "FILE", "log: write an animated GIF of the frames")
      .Option("python", "EXE", "Python with matplotlib for PNG/GIF output", "/usr/bin/python3")
      .Flag("once", "show one frame and exit (live: the first; log: the one with the largest command)")
      .Option("sed-scale-Pa", "PA", "SED colour scale [Pa] (default: log: the log's largest SED; live: each frame's peak)")
      .Flag("no-color", "plain ASCII shades instead of ANSI colours")
      .Epilog(
          "examples:\n"
          "  sedbridge display-view                                  # live, default udpm URL\n"
          "  sedbridge display-view --log out/run.lcmlog --speed 0.5\n"
          "  sedbridge display-view --log out/run.lcmlog --png-dir out/frames --animation out/run.gif\n"
          "exit status: 0 ok, 1 error, 2 usage, 3 live mode received no command");
  if (!args.Parse(argc, argv)) return 0;

  LcmChannels ch;
  ch.command = args.Get("command-channel");
  ch.sed = args.Get("sed-channel");
  ch.status = args.Get("status-channel");
  if (!IsUpperSnake(ch.command) || !IsUpperSnake(ch.sed) || !IsUpperSnake(ch.status))
    throw UsageError("channel names must be UPPER_SNAKE");
  HeatmapStyle style;
  style.color = !args.GetFlag("no-color");
  if (args.Has("sed-scale-Pa")) {
    style.sed_full_scale_Pa = args.GetDouble("sed-scale-Pa");
    if (!(style.sed_full_scale_Pa > 0)) throw UsageError("--sed-scale-Pa must be > 0");
  }
  const bool clear = style.color && ::isatty(STDOUT_FILENO) && !args.GetFlag("once");
  LayoutSource layouts(args.GetOptional("profile").value_or(""));

  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  const auto log = args.GetOptional("log");
  if (!log) {
    if (args.Has("png-dir") || args.Has("animation"))
      throw UsageError("--png-dir/--animation need --log (record live runs with lcm-logger)");
    return RunLive(args, ch, layouts, style, clear);
  }
  std::size_t bad = 0;
  const long max_frames = args.GetInt("max-frames");
  if (max_frames < 1) throw UsageError("--max-frames must be >= 1");
  const std::vector<DisplayFrame> frames =
      ReadDisplayFrames(*log, ch, args.GetDouble("fps"), static_cast<std::size_t>(max_frames), &bad);
  if (bad) std::fprintf(stderr, "display-view: %zu events did not decode (wrong type?)\n", bad);
  if (frames.empty()) {
    std::fprintf(stderr, "display-view: no %s events in %s\n", ch.command.c_str(), log->c_str());
    return 1;
  }
  if (args.Has("png-dir") || args.Has("animation")) return RunLogImages(args, frames, layouts);
  return RunLogTerminal(args, frames, layouts, style, clear);
}

}  // namespace
}  // namespace sedbridge::app

SEDBRIDGE_COMMAND(display_view, "display-view",
                  "show display commands + SED as a terminal heatmap, PNG frames or a GIF",
                  &sedbridge::app::RunDisplayView);
