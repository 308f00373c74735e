#pragma once
// Offline runs of the bridge: every frame of a finite source (candump log, simulated sensor)
// through the assembler and the pipeline, every scan processed, in order. Everything
// published and written is stamped with the source's own time (the log's receive times), so
// two runs give identical output; only the measured wall-clock latency differs.
//
// Files written into `out_dir` (when not empty):
//   summary.csv             one row per scan: utime,total_force_N,applied_force_N,max_sed_Pa,
//                           max_command,latency_ms,stepped,invalid_taxels
//   peak_merkel_sed.csv     x_mm,y_mm,z_mm,sed_Pa of the Merkel layer at the scan of peak SED
//   peak_command.csv        actuator,x_mm,y_mm,value (display unit) at that scan
//   peak_taxels.csv         taxel,x_mm,y_mm,pressure_Pa,health (pad frame, registered) at that
//                           scan; health: ok, stuck, dead, frozen (masked), drifting (re-tared)
//   peak_display_sed.csv    inverse rendering only: vertex,x_mm,y_mm,z_mm,sed_Pa, the SED the
//                           published commands at that scan add to the leader's preloaded pad
//                           (full contact FE), the same vertices as peak_merkel_sed.csv
//   stage_ms.csv            one row per scan: utime, then the wall time [ms] of each stage
//                           (common/stage_times.h), then scan_cpu_ms (the whole scan's
//                           thread-CPU time); apart from summary.csv, which stays
//                           identical between runs but for latency_ms
//   bridge.lcmlog           every published LCM message (lcm-logplayer, lcm-spy)
//   frames.pvd, frame_*.vtu with vtu_every > 0 (ParaView)

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bridge/bridge_config.h"
#include "bridge/bridge_pipeline.h"
#include "bridge/display_fidelity.h"
#include "bridge/fe_step.h"
#include "bridge/latency_stats.h"
#include "bridge/leader_model_cache.h"
#include "display/display_profile.h"
#include "sensors/frame_source.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::bridge {

struct ReplayOptions {
  std::string out_dir;             ///< "" = no files (tests)
  std::string lcm_url = "memq://"; ///< where messages go besides the log (memq = nowhere)
  bool write_lcm_log = true;       ///< bridge.lcmlog in out_dir
  bool progress = false;           ///< a line on stderr every 1000 scans
  /// Every N-th stepped scan, write out_dir/frames.pvd + frame_NNNNNN.vtu (reference soft mesh
  /// with displacement_mm, merkel_sed_Pa, and traction_pad_Pa with the scene step; see
  /// scene/vtu_writer.h). Works with the scene and the reduced step. 0 = none.
  int vtu_every = 0;
  /// Called after every scan (tests, benchmarks), with the pipeline (e.g. to drain memq).
  std::function<void(const ScanOutcome&, BridgePipeline&)> on_scan;
  /// Called once the pipeline exists, before the first frame (e.g. to subscribe on memq).
  std::function<void(BridgePipeline&)> on_start;
  /// Called after the display's shutdown, before the pipeline is destroyed.
  std::function<void(BridgePipeline&)> on_finish;
  /// Set (e.g. by a signal handler) to end the run early: the display is driven to zero, the
  /// log closed and the files written as at the source's end. nullptr = run to the end.
  const std::atomic<bool>* stop = nullptr;
  /// Only frames from this CAN interface are the sensor's (a candump of can0 and can1 is not
  /// merged); others are counted (BadFrameCounters::other_interface). "" = any.
  std::string can_interface;
  /// > 0 when the source is paced at this multiple of its recorded speed (a live replay):
  /// then the display is ticked every `idle_tick_period_us` of wall time while no frame
  /// arrives, so its watchdog ramps it to zero through a pause in the log, as in `run`.
  /// Ticks are stamped in log time (last scan + elapsed wall time x speed). 0 = unpaced.
  double paced_speed = 0;
  int64_t idle_tick_period_us = 5000;  ///< [us], > 0
  /// A hand (RunHandReplay): threads the fingers run on (bridge/finger_workers.h: each
  /// finger on one thread, its scans in order, so the output is the same for any count);
  /// the callbacks above are then called on those threads. 1 = the caller's thread.
  int finger_threads = 1;
};

struct ReplayRow {
  int64_t utime = 0;
  double total_force_N = 0, applied_force_N = 0, max_sed_Pa = 0, max_command = 0, latency_ms = 0;
  bool stepped = false;
  int invalid_taxels = 0;
  StageTimes stage_ms;  ///< wall time per stage (ScanOutcome::stage_ms)
  /// CPU time the scan took its thread [ms] (ProcessScan; the FE's own OpenMP threads, when
  /// more than one, not counted): its cost without the time it waited preempted.
  double cpu_ms = 0;
};

struct ReplayResult {
  std::vector<ReplayRow> rows;
  PipelineCounters counters;
  LatencySummary latency;
  StageTimes stage_p50_ms;      ///< median per stage over the stepped scans that ran it [ms]
  sensors::BadFrameCounters bad_frames;
  sensors::FrameSourceStats source_stats;
  double wall_s = 0;            ///< processing time (scan loop only, no model load)
  double setup_s = 0;           ///< model load + factorization
  int peak_index = -1;          ///< row of peak SED
  std::string fe_description;
  std::string taxel_health;     ///< sensors::TaxelHealth::Summary() at the end
  std::string fe_counters;      ///< FeStep::CountersLine() at the end ("" = none)
  std::string display_unit;
  int64_t published = 0, publish_errors = 0;
  /// The highest command the display can get: min(mapping saturation, safety max) [unit]
  /// (inverse rendering: safety max, the renderer's bound).
  double command_ceiling = 0;
  bool ceiling_is_mapping = true;     ///< the mapping's saturation (silent), not the limiter's max (clamped)
  int display_actuators = 0;
  int peak_actuators_at_ceiling = 0;  ///< actuators at command_ceiling in the peak-SED command
  int64_t scans_at_ceiling = 0;       ///< scans whose largest command reached command_ceiling
  /// Which rendering the display got and why (bridge/display_requests.h).
  std::string display_rendering;
  bool inverse_rendering = false;
  LatencySummary render_ms;            ///< inverse: the renderer's wall time per scan
  LatencySummary render_cpu_ms;        ///< inverse: its CPU time per scan (load left out)
  int64_t render_not_converged = 0;    ///< inverse: scans whose renderer stopped at its iteration limit
  int render_evaluations_median = 0, render_evaluations_p99 = 0, render_evaluations_max = 0;  ///< inverse: SED evaluations a render
  /// Inverse: the display's SED at the peak scan (published commands, full FE) against the
  /// bridge's; have_display_fidelity false (reason in display_fidelity_error) if not computed.
  bool have_display_fidelity = false;
  DisplayFidelity display_fidelity;
  std::string display_fidelity_error;
  /// Electrotactile (no mechanical load): the SA1 rate ESTIMATE (display/sa1_rate_estimate.h,
  /// bridge/sa1_rate_at_peak.h) at the electrodes from the SED asked at the peak scan.
  bool have_sa1_estimate = false;
  int sa1_peak_electrode = -1;
  double sa1_peak_rate_estimate_Hz = 0;  ///< the largest, at sa1_peak_electrode [spikes/s]
  double sa1_peak_site_sed_Pa = 0;       ///< the SED sampled at that electrode [Pa]
  int64_t idle_ticks = 0;       ///< display ticks while a paced source was silent
  bool stopped_early = false;   ///< `stop` was set before the source's end
};

/// Runs `source` to its end (or until options.stop) through a new pipeline built from
/// `config` and the profiles the caller loaded (config.sensor_profile, config.display_profile).
/// `fe`: a given FE step (e.g. one already built; ownership passes to the pipeline), or
/// nullptr to build it from `config`. On every way out — end, stop, or an exception from the
/// source, a stage or a callback — the display is shut down (zero published) and the LCM log
/// closed before returning or rethrowing.
ReplayResult RunReplay(const BridgeConfig& config, const sensors::SensorProfile& profile,
                       const display::DisplayProfile& display_profile, std::unique_ptr<FeStep> fe,
                       sensors::FrameSource& source, const ReplayOptions& options);

/// One finger of a hand's replay (bridge/fingers.h: FingersOf gives name and config).
struct HandFinger {
  std::string name;
  BridgeConfig config;                   ///< the finger's (its channels, interface, ids)
  sensors::SensorProfile profile;        ///< its ids already moved (LoadFingerSensorProfile)
  display::DisplayProfile display_profile;
  std::unique_ptr<FeStep> fe;            ///< nullptr: built from config
};

struct HandReplayResult {
  std::vector<std::string> names;        ///< the fingers, in config order
  std::vector<ReplayResult> fingers;     ///< one per finger, same order
  /// Frames no finger claimed, per interface (sensors::FrameRouter).
  std::map<std::string, int64_t> unclaimed_frames;
  int64_t frames = 0;                    ///< frames read from the source
  /// Leader models (fe.step contact) loaded, and taken by a later finger from an earlier one
  /// (the model; its compliance precompute), bridge/leader_model_cache.h.
  int leader_models_loaded = 0, leader_models_shared = 0, leader_operators_shared = 0;
  /// Inverse display renderings precomputed, and taken by a later finger with the same
  /// leader model and display (InverseRenderingCache).
  int display_renderings_built = 0, display_renderings_shared = 0;
  /// Fingers that took the pressure-map step's precompute from an earlier one (same leader
  /// model and sensor profile: the contact step's fallback or fe.step reduced).
  int fallbacks_shared = 0;
  double wall_s = 0;                     ///< the scan loop, all fingers
  int finger_threads = 1;                ///< threads the fingers ran on
  bool stopped_early = false;
};

/// A hand: every finger's frames from one source (a `candump -l any` log of several buses),
/// routed by interface and CAN id to that finger's assembler, each scan through that
/// finger's pipeline, one finger after another in the order the log gives (deterministic:
/// a replay gives the same files run to run, on any options.finger_threads). While one finger's sensor is silent and
/// another's scans come, the silent one's display is ticked in log time at its rates.tick_Hz,
/// so its watchdog ramps it to zero while the others go on. Every way out zeroes every
/// display. Files: RunReplay's, in out_dir/<finger name>/ for each finger. Throws
/// std::invalid_argument when two fingers claim one CAN id on one interface.
HandReplayResult RunHandReplay(std::vector<HandFinger> fingers, sensors::FrameSource& source,
                               const ReplayOptions& options);

/// Builds every finger's FE step that is still null, leader models first, in config order: a
/// finger whose leader model fails to load throws (naming the finger and the model) before
/// any display session exists. The same leader model named twice is loaded and precomputed
/// once through `leaders` and shared read-only. `full_field`: MakeFeStep's. For the hand's
/// replay and live `run` alike.
void BuildHandFeSteps(std::vector<HandFinger>& fingers, bool full_field, LeaderModelCache* leaders);

/// Writes summary.csv for `rows`.
void WriteSummaryCsv(const std::string& path, const std::vector<ReplayRow>& rows);
/// Writes stage_ms.csv for `rows`: utime, one column per stage named `<stage>_ms` (wall
/// time), then scan_cpu_ms (ReplayRow::cpu_ms).
void WriteStageCsv(const std::string& path, const std::vector<ReplayRow>& rows);

}  // namespace sedbridge::bridge
