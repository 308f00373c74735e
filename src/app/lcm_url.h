#pragma once
// Which LCM URL a command talks on. One order for every command, so a lab sets the URL once
// (in the shell, for all tools LCM ships too) and overrides it per run:
//   1. --lcm-url URL            (the command line)
//   2. $LCM_DEFAULT_URL          (the environment; LCM's own tools read it as well)
//   3. the command's fallback    (run: the bridge config's lcm.url; replay and simulate:
//                                 memq://, i.e. only the log file; display-view: LCM's
//                                 multicast default with ttl=0)
// docs/two-host.md shows a two-host setup.

#include <optional>
#include <string>

namespace sedbridge::app {

struct LcmUrlChoice {
  std::string url;     ///< the LCM provider URL to open, e.g. "udpm://239.255.76.67:7667?ttl=1"
  std::string source;  ///< where it came from: "--lcm-url", "LCM_DEFAULT_URL" or `fallback_source`
};

/// @param[in] flag             value of --lcm-url, if given (an empty value is a usage error)
/// @param[in] fallback         URL when neither the flag nor a non-empty $LCM_DEFAULT_URL is set
/// @param[in] fallback_source  how to name the fallback in messages, e.g. "config lcm.url"
/// Throws UsageError for an empty --lcm-url.
LcmUrlChoice ChooseLcmUrl(const std::optional<std::string>& flag, const std::string& fallback,
                          const std::string& fallback_source);

/// One line for --help: the order above, naming this command's fallback.
std::string LcmUrlHelp(const std::string& fallback_description);

}  // namespace sedbridge::app
