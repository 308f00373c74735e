#pragma once
// The output options `replay` and `simulate` share (--out, --lcm-url, --vtu-every, --quiet):
// both run the same pipeline and write the same files.

#include "app/arg_parser.h"
#include "bridge/bridge_config.h"
#include "bridge/replay.h"

namespace sedbridge::app {

/// Reads --out, --lcm-url, --vtu-every and --quiet (declared by the command) into
/// ReplayOptions (the LCM URL in the order of app/lcm_url.h, fallback memq://).
bridge::ReplayOptions ReadReplayOutputOptions(const ArgParser& args, const bridge::BridgeConfig& config);

}  // namespace sedbridge::app
