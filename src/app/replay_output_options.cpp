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

std::string SaturationNote(const bridge::ReplayResult& r) {
  if (r.scans_at_ceiling == 0) return "";
  char buf[200];
  std::snprintf(buf, sizeof buf, " (%d/%d actuators at the %g %s ceiling: %s; %lld of %zu scans reached it)",
                r.peak_actuators_at_ceiling, r.display_actuators, r.command_ceiling, r.display_unit.c_str(),
                r.ceiling_is_mapping ? "the SED mapping saturates" : "the safety limiter clips",
                static_cast<long long>(r.scans_at_ceiling), r.rows.size());
  return buf;
}

std::vector<std::string> PlotBridgeArgs(const std::string& out_dir, const bridge::ReplayResult& r) {
  char ceiling[32];
  std::snprintf(ceiling, sizeof ceiling, "%g", r.command_ceiling);
  return {out_dir, r.display_unit, ceiling};
}

}  // namespace sedbridge::app
