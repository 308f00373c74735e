#include "app/replay_output_options.h"

#include <cstdio>

#include "app/lcm_url.h"

namespace sedbridge::app {

bridge::ReplayOptions ReadReplayOutputOptions(const ArgParser& args, const bridge::BridgeConfig& config) {
  bridge::ReplayOptions options;
  options.out_dir = args.Get("out");
  const LcmUrlChoice url = ChooseLcmUrl(args.GetOptional("lcm-url"), "memq://", "default");
  options.lcm_url = url.url;
  if (url.source != "default") std::printf("LCM: also publishing on %s (from %s)\n", url.url.c_str(), url.source.c_str());
  options.progress = !args.GetFlag("quiet");
  options.vtu_every = static_cast<int>(args.GetInt("vtu-every"));
  if (options.vtu_every < 0) throw UsageError("--vtu-every must be >= 0");
  return options;
}

}  // namespace sedbridge::app
