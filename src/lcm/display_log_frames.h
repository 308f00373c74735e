#pragma once
// Frames for viewing a recorded run: sample an LCM log's DISPLAY_COMMAND / FINGERTIP_SED
// events at a fixed frame rate, and write them as JSON lines for tools/plot_display_frames.py.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "display/display_command.h"
#include "display/sed_field.h"
#include "display/terminal_heatmap.h"
#include "lcm/lcm_channels.h"

namespace sedbridge::lcm_io {

struct DisplayFrame {
  int64_t log_utime = 0;    ///< log timestamp of the command shown [us]
  display::DisplayCommand command;
  bool has_sed = false;     ///< a SED field was seen at or before this command
  display::SedField sed;             ///< the latest one
  /// lcmt_bridge_status::taxel_health[] of the latest BRIDGE_STATUS at or before this
  /// command (empty: none seen, or it reported no taxels).
  std::vector<int8_t> taxel_health;
};

/// Reads `log_path` and keeps one command per 1/fps of log time (the first command at or after
/// each frame time), each with the latest SED field before it; the last command of the log is
/// always kept (it is the shutdown command of a clean run). At most `max_frames`.
/// fps <= 0 keeps every command. Events that do not decode are counted in `bad_events`.
/// Throws std::runtime_error if the log cannot be opened.
std::vector<DisplayFrame> ReadDisplayFrames(const std::string& log_path,
                                            const LcmChannels& channels, double fps,
                                            std::size_t max_frames, std::size_t* bad_events = nullptr);

/// Writes a header line {"display_id","unit","max","x_mm","y_mm"} and one line per frame
/// {"utime","sequence","value","clamped","stale","fault","shutdown","sed":{...}|null}.
/// Non-finite numbers are written as null (JSON has no NaN). Throws std::runtime_error.
void WriteFramesJsonl(const std::string& path, const display::ActuatorLayout& layout,
                      const std::string& display_id, const std::vector<DisplayFrame>& frames);

}  // namespace sedbridge::lcm_io
