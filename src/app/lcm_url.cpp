#include "app/lcm_url.h"

#include <cstdlib>

#include "app/arg_parser.h"

namespace sedbridge::app {

LcmUrlChoice ChooseLcmUrl(const std::optional<std::string>& flag, const std::string& fallback,
                          const std::string& fallback_source) {
  if (flag) {
    if (flag->empty()) throw UsageError("--lcm-url needs a URL (e.g. udpm://239.255.76.67:7667?ttl=1)");
    return {*flag, "--lcm-url"};
  }
  // An empty variable counts as unset, as in LCM's own lcm_create().
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); env && *env) return {env, "LCM_DEFAULT_URL"};
  return {fallback, fallback_source};
}

std::string LcmUrlHelp(const std::string& fallback_description) {
  return "LCM URL to publish on; default: $LCM_DEFAULT_URL if set, else " + fallback_description;
}

}  // namespace sedbridge::app
