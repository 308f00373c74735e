#pragma once
// What `replay` and `simulate` print and plot for a bridge run: one finger's summary, and a
// hand's (`fingers:`) fingers as they are loaded and its per-finger summaries, plots and
// totals. Both commands run the same pipeline (bridge/replay.h) and write the same files.

#include <string>
#include <vector>

#include "app/stop_signals.h"
#include "bridge/bridge_config.h"
#include "bridge/replay.h"

namespace sedbridge::app {

/// One finger's summary lines (scans, frames, peak, rendering, timing, stages, counters);
/// `out` the folder its files went to ("" none).
void PrintReplaySummary(const bridge::ReplayResult& r, const std::string& out);

/// The fingers of a config with `fingers:`, each with its sensor profile (ids moved) and
/// display profile loaded; prints a line per finger.
std::vector<bridge::HandFinger> LoadHandFingers(const bridge::BridgeConfig& config);

/// A hand's run, reported: each finger's summary (and plots unless `no_plots`) from
/// out_dir/<finger>/, the hand's totals, what was shared and the frames no finger claimed.
/// Returns the exit status: 128 + signal when stopped by one, 1 (an error naming `command`)
/// when no finger made a scan, else 0.
int ReportHandReplay(const std::string& command, const bridge::HandReplayResult& hand, const std::string& out_dir,
                     bool no_plots, const StopSignals& signals);

}  // namespace sedbridge::app
