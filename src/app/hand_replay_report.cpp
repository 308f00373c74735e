#include "app/hand_replay_report.h"

#include <cstdio>
#include <vector>

#include "app/plot_runner.h"
#include "app/replay_output_options.h"
#include "bridge/fingers.h"
#include "display/display_profile.h"

namespace sedbridge::app {

using namespace sedbridge::bridge;

void PrintReplaySummary(const ReplayResult& r, const std::string& out) {
  const PipelineCounters& c = r.counters;
  std::printf("%s\n", r.fe_description.c_str());
  std::printf("scans: %lld (stepped %lld, rejected %lld, FE failures %lld), invalid taxel readings %lld, "
              "NaN values caught %lld\n",
              static_cast<long long>(c.scans), static_cast<long long>(c.steps), static_cast<long long>(c.scans_rejected),
              static_cast<long long>(c.fe_failures), static_cast<long long>(c.invalid_taxels),
              static_cast<long long>(c.nonfinite_values));
  std::printf("frames: %lld (rejected %lld, partial scans %lld, sensor scans dropped %lld), log bad lines %lld\n",
              static_cast<long long>(r.bad_frames.frames), static_cast<long long>(r.bad_frames.rejected()),
              static_cast<long long>(r.bad_frames.scans_partial), static_cast<long long>(r.bad_frames.scans_dropped),
              static_cast<long long>(r.source_stats.bad_lines));
  if (r.peak_index >= 0) {
    const ReplayRow& p = r.rows[size_t(r.peak_index)];
    std::printf("peak: scan %d at t = %.3f s: force %.3f N (FE applied %.3f N), max Merkel SED %.1f Pa, max command "
                "%.2f %s%s\n",
                r.peak_index, (p.utime - r.rows.front().utime) * 1e-6, p.total_force_N, p.applied_force_N,
                p.max_sed_Pa, p.max_command, r.display_unit.c_str(), SaturationNote(r).c_str());
  }
  PrintDisplayRendering(r);
  std::printf("timing: setup %.2f s; %lld scans in %.3f s = %.0f scans/s; latency median %.3f ms, p99 %.3f ms, max "
              "%.3f ms\n",
              r.setup_s, static_cast<long long>(c.scans), r.wall_s, r.wall_s > 0 ? c.scans / r.wall_s : 0.0,
              r.latency.p50_ms, r.latency.p99_ms, r.latency.max_ms);
  {
    // This thread's CPU time for each scan: the scan's own cost, without the time a shared
    // machine kept it preempted (which the wall-clock latency counts).
    std::vector<float> cpu_ms;
    cpu_ms.reserve(r.rows.size());
    for (const ReplayRow& row : r.rows) cpu_ms.push_back(static_cast<float>(row.cpu_ms));
    const double cpu_p50 = Percentile(cpu_ms, 0.5), cpu_p99 = Percentile(cpu_ms, 0.99), cpu_max = Percentile(cpu_ms, 1.0);
    std::printf("CPU per scan (this thread's CPU time, preemption left out): median %.3f ms, p99 %.3f ms, max %.3f ms\n",
                cpu_p50, cpu_p99, cpu_max);
  }
  std::printf("stages (median ms): %s\n", FormatStageTimes(r.stage_p50_ms).c_str());
  if (c.scans_rejected > 0) std::printf("rejected scans by reason: %s\n", FormatRejectCounters(c.rejected_by_reason).c_str());
  if (!r.fe_counters.empty()) std::printf("%s\n", r.fe_counters.c_str());
  if (!r.taxel_health.empty()) std::printf("%s\n", r.taxel_health.c_str());
  std::printf("LCM: %lld messages published (%lld errors)\n", static_cast<long long>(r.published),
              static_cast<long long>(r.publish_errors));
  if (!out.empty())
    std::printf("wrote %s/{summary.csv, stage_ms.csv, peak_merkel_sed.csv, peak_command.csv, peak_taxels.csv, %sbridge.lcmlog}\n",
                out.c_str(),
                r.have_display_fidelity ? "peak_display_sed.csv, " : r.have_sa1_estimate ? "peak_sa1_rate_estimate.csv, " : "");
}

std::vector<HandFinger> LoadHandFingers(const BridgeConfig& config) {
  std::vector<HandFinger> fingers;
  for (Finger& f : FingersOf(config)) {
    std::printf("finger %s: sensor %s (id offset %d) on %s, model %s/%s, display %s\n", f.name.c_str(),
                f.config.sensor_profile.c_str(), f.config.can_id_offset, f.config.can_interface.c_str(),
                f.config.model.c_str(), f.config.preset.c_str(), f.config.display_profile.c_str());
    HandFinger h{f.name, f.config, LoadFingerSensorProfile(f.config),
                 display::LoadNamedDisplayProfile(f.config.display_profile), nullptr};
    fingers.push_back(std::move(h));
  }
  std::fflush(stdout);
  return fingers;
}

int ReportHandReplay(const std::string& command, const HandReplayResult& hand, const std::string& out_dir,
                     bool no_plots, const StopSignals& signals) {
  int64_t scans = 0;
  for (size_t i = 0; i < hand.names.size(); ++i) {
    const std::string dir = out_dir.empty() ? "" : out_dir + "/" + hand.names[i];
    std::printf("\n== finger %s ==\n", hand.names[i].c_str());
    PrintReplaySummary(hand.fingers[i], dir);
    scans += static_cast<long long>(hand.fingers[i].rows.size());
    if (!no_plots && !hand.fingers[i].rows.empty() && !dir.empty() &&
        RunPlotScript("plot_bridge.py", PlotBridgeArgs(dir, hand.fingers[i])))
      std::printf("plots: %s/bridge_peak.png, %s/bridge_timeline.png\n", dir.c_str(), dir.c_str());
  }
  std::printf("\nhand: %zu fingers on %d threads, %lld frames, %lld scans in %.3f s\n", hand.names.size(),
              hand.finger_threads, static_cast<long long>(hand.frames), static_cast<long long>(scans), hand.wall_s);
  std::printf("leader models (fe.step contact): %d loaded; fingers reusing one already loaded: %d (its compliance "
              "precompute too: %d)\n",
              hand.leader_models_loaded, hand.leader_models_shared, hand.leader_operators_shared);
  if (hand.fallbacks_shared > 0)
    std::printf("pressure-map precomputes (scene, K, U) reused by a later finger with the same sensor: %d\n",
                hand.fallbacks_shared);
  if (hand.display_renderings_built > 0)
    std::printf("inverse display renderings: %d precomputed; fingers reusing one already precomputed: %d\n",
                hand.display_renderings_built, hand.display_renderings_shared);
  for (const auto& [bus, count] : hand.unclaimed_frames)
    std::printf("frames no finger claims on %s: %lld\n", bus.c_str(), static_cast<long long>(count));
  if (signals.signal_number()) {
    std::printf("stopped by %s: every display driven to zero, logs closed\n", SignalName(signals.signal_number()));
    return signals.ExitCode(0);
  }
  if (scans == 0) {
    std::fprintf(stderr, "sedbridge %s: error: no finger's frames made a scan (check each finger's sensor.interface "
                         "and ids against the %s)\n", command.c_str(), command == "replay" ? "log" : "scenes");
    return 1;
  }
  return 0;
}
}  // namespace sedbridge::app
