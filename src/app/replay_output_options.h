#pragma once
// The output options `replay` and `simulate` share (--out, --lcm-url, --vtu-every, --quiet):
// both run the same pipeline and write the same files.

#include <string>
#include <vector>

#include "app/arg_parser.h"
#include "bridge/bridge_config.h"
#include "bridge/replay.h"

namespace sedbridge::app {

/// Reads --out, --lcm-url, --vtu-every and --quiet (declared by the command) into
/// ReplayOptions (the LCM URL in the order of app/lcm_url.h, fallback memq://).
bridge::ReplayOptions ReadReplayOutputOptions(const ArgParser& args, const bridge::BridgeConfig& config);

/// "" when no command reached the display's ceiling; else e.g.
/// " (16/16 actuators at the 20 kPa ceiling: the SED mapping saturates; 120 of 200 scans reached it)".
std::string SaturationNote(const bridge::ReplayResult& result);

/// The display's lines of a replay's summary: which rendering and why; with the inverse
/// renderer its time per scan and the display fidelity at the peak scan.
void PrintDisplayRendering(const bridge::ReplayResult& result);

/// Arguments for tools/plot_bridge.py: DIR UNIT CEILING.
std::vector<std::string> PlotBridgeArgs(const std::string& out_dir, const bridge::ReplayResult& result);

}  // namespace sedbridge::app
