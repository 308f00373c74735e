// sedbridge-display-driver: the leader-side process next to the haptic display. Subscribes
// to DISPLAY_COMMAND, checks each message, applies its own limiter and watchdog from the
// display profile and writes the actuator values to the device on its own timer. Keeps
// running (and ramps to zero) when the bridge dies; exits to zero on SIGINT, SIGTERM,
// SIGHUP and SIGQUIT. Composes display/ (profile, limiter, driver core, outputs) with the LCM
// stage (src/lcm: URL and channels, size-safe decoding) and the common base only (no FE code).
// Usage: display/README.md, "Display driver".

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <map>
#include <memory>
#include <string>

#include "common/config_error.h"
#include "common/wall_clock.h"
#include "display/display_driver.h"
#include "lcm/display_command_message.h"
#include "lcm/lcm_channels.h"
#include "lcm/merkel_sed_message.h"

namespace {

using namespace sedbridge::display;
using sedbridge::WallClockUtime;
using sedbridge::lcm_io::DecodeDisplayCommand;
using sedbridge::lcm_io::IsUpperSnake;
using sedbridge::lcm_io::kDefaultLcmUrl;
using sedbridge::lcm_io::LcmChannels;

std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_signal = 0;
extern "C" void OnStopSignal(int sig) {
  if (g_signal == 0) g_signal = sig;
  g_stop.store(true);
}

constexpr const char* kUsage =
    "usage: sedbridge-display-driver --profile NAME|PATH (--key-file KEY | --no-auth) [options]\n"
    "\n"
    "The leader-side display driver: DISPLAY_COMMAND (LCM) -> own safety limiter and watchdog\n"
    "from the display profile -> actuator output, one frame per tick, whether commands arrive\n"
    "or not. No valid command within the profile's watchdog_timeout_s: ramp to zero.\n"
    "\n"
    "  --profile NAME|PATH  display profile (suction_4x4 = config/displays/suction_4x4.yaml)\n"
    "  --key-file KEY       accept only HMAC-SHA256-signed commands (key: >= 32 raw bytes, mode 600)\n"
    "  --no-auth            accept unsigned commands (anyone on the LCM network can command the display)\n"
    "  --url URL            LCM URL (default udpm://239.255.76.67:7667?ttl=0)\n"
    "  --channel NAME       command channel (default DISPLAY_COMMAND)\n"
    "  --output SPEC        stdout | csv:PATH (file or FIFO) | serial:DEVICE[:BAUD] (default stdout)\n"
    "  --tick-hz HZ         output frames per second, 50..10000 (default 200)\n"
    "  --duration-s S       stop after S seconds (default: until a signal)\n"
    "exit status: 0 at --duration-s, 128 + signal when stopped by one, 1 on errors, 2 on usage errors\n";

struct Receiver {
  DisplayDriver* driver;
  void On(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    driver->OnMessage(rbuf->data, rbuf->data_size, WallClockUtime());
  }
};

int Run(int argc, char** argv) {
  std::map<std::string, std::string> opt;
  bool no_auth = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (a == "--no-auth") {
      no_auth = true;
      continue;
    }
    if (a.rfind("--", 0) != 0 || i + 1 >= argc) {
      std::fprintf(stderr, "sedbridge-display-driver: bad argument '%s'\n%s", a.c_str(), kUsage);
      return 2;
    }
    opt[a.substr(2)] = argv[++i];
  }
  for (const auto& [k, v] : opt) {
    if (k != "profile" && k != "key-file" && k != "url" && k != "channel" && k != "output" && k != "tick-hz" &&
        k != "duration-s") {
      std::fprintf(stderr, "sedbridge-display-driver: unknown option --%s\n%s", k.c_str(), kUsage);
      return 2;
    }
  }
  if (!opt.count("profile") || no_auth == bool(opt.count("key-file"))) {
    std::fprintf(stderr, "sedbridge-display-driver: need --profile and exactly one of --key-file or --no-auth\n%s",
                 kUsage);
    return 2;
  }
  const double tick_Hz = opt.count("tick-hz") ? std::atof(opt["tick-hz"].c_str()) : 200.0;
  if (!(tick_Hz >= 50 && tick_Hz <= 10000)) {
    std::fprintf(stderr, "sedbridge-display-driver: --tick-hz must be in [50, 10000]\n");
    return 2;
  }
  const double duration_s = opt.count("duration-s") ? std::atof(opt["duration-s"].c_str()) : 0.0;
  const std::string url = opt.count("url") ? opt["url"] : kDefaultLcmUrl;
  const std::string channel = opt.count("channel") ? opt["channel"] : LcmChannels{}.command;
  if (!IsUpperSnake(channel)) {
    std::fprintf(stderr, "sedbridge-display-driver: channel '%s' is not UPPER_SNAKE\n", channel.c_str());
    return 2;
  }

  const DisplayProfile profile = LoadDisplayProfile(ResolveDisplayProfilePath(opt["profile"]));
  std::shared_ptr<const CommandAuthenticator> auth;
  if (!no_auth) auth = std::make_shared<CommandAuthenticator>(CommandAuthenticator::FromKeyFile(opt["key-file"]));
  std::signal(SIGPIPE, SIG_IGN);  // a FIFO reader going away is a counted write error, not death
  DisplayDriver driver(profile, MakeActuatorOutput(opt.count("output") ? opt["output"] : "stdout", profile.size(),
                                                   profile.unit),
                       DecodeDisplayCommand, auth);
  lcm::LCM lcm(url);
  if (!lcm.good()) throw std::runtime_error("cannot open LCM at '" + url + "'");
  Receiver receiver{&driver};
  lcm.subscribe(channel, &Receiver::On, &receiver);

  struct sigaction sa {};
  sa.sa_handler = OnStopSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) sigaction(sig, &sa, nullptr);

  std::fprintf(stderr,
               "display-driver: %s (%zu actuators, max %g %s, slew %g %s/s, watchdog %g s), %s on %s, %s, "
               "%g Hz, %s\n",
               profile.name.c_str(), profile.size(), profile.safety.max, profile.unit.c_str(),
               profile.safety.slew_rate_per_s, profile.unit.c_str(), profile.safety.watchdog_timeout_s,
               channel.c_str(), url.c_str(), driver.output().Describe().c_str(), tick_Hz,
               auth ? "HMAC-SHA256 required" : "UNAUTHENTICATED");
  const int64_t period_us = static_cast<int64_t>(1e6 / tick_Hz);
  const int64_t start = WallClockUtime();
  int64_t next_tick = start;
  try {
    while (!g_stop.load()) {
      const int64_t now = WallClockUtime();
      if (duration_s > 0 && now - start >= static_cast<int64_t>(duration_s * 1e6)) break;
      if (now >= next_tick) {
        driver.Tick(now);
        // A late tick (busy machine) is not made up in a burst; the limiter uses the real time.
        next_tick = std::max(next_tick + period_us, now);
        continue;
      }
      const int wait_ms = static_cast<int>((next_tick - now + 999) / 1000);
      // -1 also when a stop signal interrupted the wait: then the loop ends normally.
      if (lcm.handleTimeout(wait_ms) < 0 && !g_stop.load()) throw std::runtime_error("LCM receive failed");
    }
  } catch (...) {
    driver.Shutdown(WallClockUtime());  // zero before the error ends the process
    throw;
  }
  driver.Shutdown(WallClockUtime());
  const DriverCounters& c = driver.counters();
  std::fprintf(stderr,
               "display-driver: stopped (%s); messages %lld: accepted %lld, malformed %lld, unsigned/forged %lld, "
               "replayed %lld, wrong display %lld; frames %lld (%lld write errors); output at zero\n",
               g_signal ? strsignal(g_signal) : "duration", static_cast<long long>(c.messages),
               static_cast<long long>(c.accepted), static_cast<long long>(c.malformed),
               static_cast<long long>(c.unsigned_or_forged), static_cast<long long>(c.replayed),
               static_cast<long long>(c.wrong_display), static_cast<long long>(c.frames),
               static_cast<long long>(c.output_errors));
  return g_signal ? 128 + static_cast<int>(g_signal) : 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const sedbridge::config::ConfigError& e) {
    std::fprintf(stderr, "sedbridge-display-driver: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sedbridge-display-driver: %s\n", e.what());
  }
  return 1;
}
