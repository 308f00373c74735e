#pragma once
// The bridge's data path for one scan, and its health report:
//
//   Scan -> TaxelHealth (masks lying taxels) -> ScanConditioner (registration, invalid taxels, NaN guard) -> FeStep (pressure BC,
//   FE step, Merkel SED) -> SedField -> DisplaySession (mapping, safety limiter, watchdog,
//   LCM publish) ; BRIDGE_STATUS at rates.status_Hz.
//
// A scan that cannot be stepped (too many invalid taxels, wrong size, FE failure) is counted
// and skipped, and the display is sent to its safe state at once: a non-finite SED field,
// which the display stage answers with all actuators at 0 and the `fault` flag.
//
// Two clocks: `now_utime` drives everything published (message utimes, watchdog, slew,
// status period; replay passes the log's time so its output is deterministic); latency is
// measured on the wall clock from the scan's receive time to the return from the publish.
// Single-threaded: call from the one solver thread.

#include <cstdint>
#include <functional>
#include <array>
#include <memory>
#include <optional>
#include <string>

#include "bridge/bridge_config.h"
#include "bridge/fe_step.h"
#include "bridge/latency_stats.h"
#include "bridge/pipeline_status.h"
#include "common/stage_times.h"
#include "bridge/taxel_values.h"
#include "display/command_request_source.h"
#include "display/display_profile.h"
#include "lcm/display_session.h"
#include "sedbridge/lcmt_bridge_status.hpp"
#include "sensors/bad_frame_counters.h"
#include "sensors/frame_source.h"
#include "sensors/scan.h"
#include "sensors/sensor_profile.h"
#include "sensors/taxel_health.h"

namespace sedbridge::bridge {

/// What happened to one scan.
struct ScanOutcome {
  bool stepped = false;          ///< the FE step ran and its SED went to the display
  std::string problem;           ///< why not (empty when stepped)
  std::optional<RejectReason> reject_reason;  ///< set when the scan was rejected
  double total_force_N = 0;      ///< measured normal force of the scan (conditioned)
  double applied_force_N = 0;    ///< force the FE applied (equals total_force_N up to unmapped taxels)
  double max_sed_Pa = 0;         ///< largest Merkel-layer SED
  double max_command = 0;        ///< largest actuator value published [display unit]
  int64_t latency_us = 0;        ///< receive (wall) -> publish (wall)
  int invalid_taxels = 0;
  int masked_taxels = 0;         ///< of those, left out by taxel health (sensors/taxel_health.h)
  fem::StepReport report;
  /// Wall time per stage of this scan: conditioning, the FE step's stages, limiter, publish.
  StageTimes stage_ms;
};

/// Counters since start.
struct PipelineCounters {
  int64_t scans = 0;              ///< scans handed to ProcessScan
  int64_t steps = 0;              ///< scans stepped
  int64_t scans_rejected = 0;     ///< scans not stepped (conditioning or FE failure)
  RejectCounters rejected_by_reason;  ///< scans_rejected, per reason
  int64_t fe_failures = 0;        ///< of those, FE step failures
  int64_t nonfinite_values = 0;   ///< NaN/Inf taxel values caught (never reached the FE)
  int64_t invalid_taxels = 0;     ///< invalid taxel readings (filled or zeroed)
  int64_t scans_dropped = 0;      ///< dropped before the pipeline (newest-scan slot, sensor counter gaps)
  int64_t commands = 0;           ///< commands published (fields + ticks)
  int64_t status_messages = 0;
};

class BridgePipeline {
 public:
  using WallClock = std::function<int64_t()>;

  /// @param[in] config    bridge config (rates, outputs, conditioning)
  /// @param[in] profile   sensor profile the scans come from
  /// @param[in] display_profile  the display the commands are for, already loaded by the caller
  ///                      (the app: display::LoadNamedDisplayProfile(config.display_profile))
  /// @param[in] fe        FE step implementation (owned)
  /// @param[in] lcm       where to publish (URL, channels, optional log)
  /// @param[in] wall_clock  for latency [us]; defaults to WallClockUtime
  /// @param[in] requests  where the display's requests come from (bridge/display_requests.h:
  ///                      the inverse renderer); empty: the profile's curve
  BridgePipeline(const BridgeConfig& config, const sensors::SensorProfile& profile,
                 display::DisplayProfile display_profile, std::unique_ptr<FeStep> fe,
                 const lcm_io::LcmSettings& lcm, WallClock wall_clock = {},
                 display::CommandRequestSource requests = {});
  ~BridgePipeline();

  /// Runs one scan through the chain. `receive_wall_utime`: wall time the scan's last
  /// frame was received (latency origin). Never throws for bad data.
  ScanOutcome ProcessScan(const sensors::Scan& scan, int64_t now_utime, int64_t receive_wall_utime);
  /// No scan this period: keeps the display watchdog honest; publishes status when due.
  void Tick(int64_t now_utime);
  /// Display to zero (published), final status. Idempotent.
  void Shutdown(int64_t now_utime);

  /// Latest sensor-side counters (copied into the status message).
  void SetSensorCounters(const sensors::BadFrameCounters& counters, const sensors::FrameSourceStats& source);
  /// Scans dropped before reaching the pipeline (newest-scan slot), total since start.
  void SetScansDroppedUpstream(int64_t dropped) { dropped_upstream_ = dropped; }

  /// Status as published (also used for the exit summary).
  lcmt_bridge_status MakeStatus(int64_t now_utime) const;

  const PipelineCounters& counters() const { return counters_; }
  const LatencyStats& latency() const { return latency_; }
  /// Per-stage wall time of the stepped scans that ran the stage (ScanOutcome::stage_ms),
  /// window and run.
  const LatencyStats& stage_stats(Stage stage) const { return stage_stats_[static_cast<size_t>(stage)]; }
  /// Median per stage over the run's stepped scans that ran it [ms] (0: never ran).
  StageTimes RunStageMedians_ms() const;
  /// The SED [Pa] the display's last requested commands add to the leader's preloaded pad, per
  /// Merkel vertex, and those commands (the inverse renderer's own evaluation at its answer:
  /// InverseDisplayRequests::PredictedSed).
  using PredictedSed = std::function<void(Eigen::VectorXd* added_sed_Pa, std::vector<double>* commands)>;
  /// With one set (inverse rendering), each stepped scan's command is followed, at most
  /// config.rendering_Hz times a second on the pipeline clock, by DISPLAY_RENDERING: the
  /// target and what the commands deliver by the model.
  void SetPredictedSed(PredictedSed predicted) { predicted_sed_ = std::move(predicted); }
  lcm_io::DisplaySession& display() { return *display_; }
  FeStep& fe() { return *fe_; }
  const ScanConditioner& conditioner() const { return conditioner_; }
  /// Which taxels lie (frozen, stuck high, dead, drifting): masked before conditioning.
  const sensors::TaxelHealth& taxel_health() const { return health_; }
  /// Last field sent to the display (finite SED of the last stepped scan).
  const display::SedField& last_field() const { return field_; }
  const TaxelValues& last_values() const { return values_; }
  const display::DisplayCommand& last_command() const { return display_->last_command(); }
  /// With a reason in fault_message().
  FaultState fault_state() const { return fault_state_; }
  const std::string& fault_message() const { return fault_message_; }

 private:
  // The stages of ProcessScan, in order. ConditionScan and StepFe return false when they
  // rejected the scan (Reject: counted, display to its safe state).
  void CountScan(int64_t now_utime);
  /// Taxel health: the scan with its masked taxels invalid (sensors/taxel_health.h).
  const sensors::Scan& JudgeTaxels(const sensors::Scan& scan, ScanOutcome* outcome);
  void PublishScan(const sensors::Scan& scan, ScanOutcome* outcome);
  bool ConditionScan(const sensors::Scan& scan, int64_t now_utime, ScanOutcome* outcome);
  bool StepFe(const sensors::Scan& scan, int64_t now_utime, ScanOutcome* outcome);
  void SendToDisplay(int64_t now_utime, int64_t receive_wall_utime, ScanOutcome* outcome);
  void PublishContact(int64_t now_utime, ScanOutcome* outcome);
  void PublishRendering(int64_t now_utime);
  void RecordStageTimes(const StageTimes& stage_ms);

  void Reject(RejectReason reason, const std::string& why, int64_t now_utime, ScanOutcome* outcome);
  void MaybePublishStatus(int64_t now_utime);

  BridgeConfig config_;
  sensors::SensorProfile profile_;
  std::unique_ptr<FeStep> fe_;
  ScanConditioner conditioner_;
  sensors::TaxelHealth health_;
  std::unique_ptr<lcm_io::DisplaySession> display_;
  WallClock wall_clock_;
  PredictedSed predicted_sed_;
  int64_t last_rendering_utime_ = 0;
  bool rendering_published_ = false;
  Eigen::VectorXd delivered_Pa_;  // PublishRendering's, kept between calls
  std::vector<double> rendered_;

  TaxelValues values_;
  display::SedField field_, fault_field_;
  LatencyStats latency_;
  // Stage medians are a summary: 100k kept samples per stage bound their memory (1 MB in all).
  static constexpr int64_t kMaxStageRunSamples = 100'000;
  std::array<LatencyStats, kNumStages> stage_stats_;
  PipelineCounters counters_;
  sensors::BadFrameCounters sensor_counters_;
  sensors::FrameSourceStats source_stats_;
  int64_t dropped_upstream_ = 0;

  // Status window.
  int64_t status_period_us_;
  int64_t window_start_utime_ = -1;
  int64_t window_scans_ = 0, window_steps_ = 0, window_commands_ = 0, window_invalid_ = 0;
  int64_t model_inadequate_scans_ = 0;  // since start: CONTACT_ESTIMATE model_inadequate (BRIDGE_STATUS)
  double window_rates_[3] = {0, 0, 0};
  LatencySummary window_latency_;
  StageTimes window_stage_p50_ms_;
  fem::StepReport last_report_;
  FaultState fault_state_ = FaultState::kOk;
  std::string fault_message_;
  bool shut_down_ = false;
};

}  // namespace sedbridge::bridge
