#include "bridge/bridge_pipeline.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "lcm/contact_estimate_message.h"
#include "lcm/lcm_float.h"
#include "lcm/taxel_health_message.h"
#include "lcm/tactile_scan_message.h"
#include "sedbridge/lcmt_display_rendering.hpp"

namespace sedbridge::bridge {

BridgePipeline::BridgePipeline(const BridgeConfig& config, const sensors::SensorProfile& profile,
                               display::DisplayProfile display_profile, std::unique_ptr<FeStep> fe,
                               const lcm_io::LcmSettings& lcm, WallClock wall_clock,
                               display::CommandRequestSource requests)
    : config_(config),
      profile_(profile),
      fe_(std::move(fe)),
      conditioner_(profile, PadRegistration(profile.taxels, config.registration), config.conditioning),
      health_(profile),
      wall_clock_(wall_clock ? std::move(wall_clock) : WallClock(WallClockUtime)),
      status_period_us_(std::max<int64_t>(1, static_cast<int64_t>(std::llround(1e6 / config.status_Hz)))) {
  stage_stats_.fill(LatencyStats(kMaxStageRunSamples));
  lcm_io::DisplaySessionOptions options;
  options.publish_sed = config.publish_sed;
  options.requests = std::move(requests);
  display_ = std::make_unique<lcm_io::DisplaySession>(std::move(display_profile), lcm, options);
  const Eigen::Matrix3Xd& rest = fe_->merkel_rest_pad_mm();
  field_.model_id = fe_->model_id();
  field_.x_mm.resize(size_t(rest.cols()));
  field_.y_mm.resize(size_t(rest.cols()));
  field_.z_mm.resize(size_t(rest.cols()));
  for (Eigen::Index k = 0; k < rest.cols(); ++k) {
    field_.x_mm[size_t(k)] = rest(0, k);
    field_.y_mm[size_t(k)] = rest(1, k);
    field_.z_mm[size_t(k)] = rest(2, k);
  }
  field_.sed_Pa.assign(size_t(rest.cols()), 0.0);
  fault_field_ = field_;
  std::fill(fault_field_.sed_Pa.begin(), fault_field_.sed_Pa.end(), std::numeric_limits<double>::quiet_NaN());
}

BridgePipeline::~BridgePipeline() {
  try {
    Shutdown(WallClockUtime());
  } catch (...) {
  }
}

void BridgePipeline::Reject(RejectReason reason, const std::string& why, int64_t now_utime, ScanOutcome* outcome) {
  ++counters_.scans_rejected;
  ++counters_.rejected_by_reason[reason];
  outcome->problem = why;
  outcome->reject_reason = reason;
  fault_state_ = FaultState::kFault;
  fault_message_ = "scan rejected: " + why;
  fault_field_.utime = now_utime;
  const display::DisplayCommand& c = display_->OnSedField(fault_field_, now_utime);
  ++counters_.commands;
  ++window_commands_;
  outcome->max_command = c.value.empty() ? 0 : *std::max_element(c.value.begin(), c.value.end());
  outcome->latency_us = 0;
}

// The stages of one scan, in order, as MuJoCo's mj_step: each records its own counters and
// stage time; a stage that rejects the scan ends it (the display already sent to zero).
ScanOutcome BridgePipeline::ProcessScan(const sensors::Scan& scan, int64_t now_utime, int64_t receive_wall_utime) {
  ScanOutcome outcome;
  if (shut_down_) {
    outcome.problem = "shut down";
    return outcome;
  }
  CountScan(now_utime);
  const sensors::Scan& judged = JudgeTaxels(scan, &outcome);
  PublishScan(judged, &outcome);
  if (ConditionScan(judged, now_utime, &outcome) && StepFe(judged, now_utime, &outcome)) {
    SendToDisplay(now_utime, receive_wall_utime, &outcome);
    PublishContact(now_utime, &outcome);
    PublishRendering(now_utime);
    RecordStageTimes(outcome.stage_ms);
    if (fault_state_ == FaultState::kFault) fault_state_ = FaultState::kOk, fault_message_.clear();
  }
  MaybePublishStatus(now_utime);
  return outcome;
}

void BridgePipeline::CountScan(int64_t now_utime) {
  if (window_start_utime_ < 0) window_start_utime_ = now_utime;
  ++counters_.scans;
  ++window_scans_;
}

void BridgePipeline::PublishScan(const sensors::Scan& scan, ScanOutcome* outcome) {
  if (!config_.publish_scans) return;
  const StageTimer timer(outcome->stage_ms, Stage::kPublish);
  display_->publisher().Publish(display_->publisher().channels().tactile_scan, lcm_io::ToLcm(scan, profile_.name));
}

const sensors::Scan& BridgePipeline::JudgeTaxels(const sensors::Scan& scan, ScanOutcome* outcome) {
  // Masked taxels are invalid from here on: TACTILE_SCAN's valid[] shows them, they carry no
  // weight in the contact fit and no pressure of their own in the pressure map.
  const StageTimer timer(outcome->stage_ms, Stage::kConditioning);
  const sensors::Scan& judged = health_.Apply(scan);
  outcome->masked_taxels = health_.left_out();
  return judged;
}

bool BridgePipeline::ConditionScan(const sensors::Scan& scan, int64_t now_utime, ScanOutcome* outcome) {
  fault_field_.source_scan_utime = scan.utime;
  StageTimer conditioning_timer(outcome->stage_ms, Stage::kConditioning);
  const ConditioningReport cr = conditioner_.Condition(scan, &values_);
  conditioning_timer.Stop();
  counters_.nonfinite_values += cr.nonfinite_values;
  counters_.invalid_taxels += cr.invalid_taxels;
  window_invalid_ += cr.invalid_taxels;
  outcome->invalid_taxels = cr.invalid_taxels;
  if (!cr.usable) {
    Reject(cr.reject_reason, cr.reason, now_utime, outcome);
    return false;
  }
  outcome->total_force_N = values_.total_force_N;
  return true;
}

bool BridgePipeline::StepFe(const sensors::Scan& scan, int64_t now_utime, ScanOutcome* outcome) {
  const MerkelSedResult& r = fe_->Step(values_);
  outcome->report = r.report;
  last_report_ = r.report;
  outcome->applied_force_N = r.applied_force_N;
  outcome->stage_ms.Add(r.report.stage_ms);
  if (!r.ok || !r.sed_Pa || static_cast<size_t>(r.sed_Pa->size()) != field_.sed_Pa.size()) {
    ++counters_.fe_failures;
    if (r.ok) Reject(RejectReason::kSedSizeMismatch, "SED size mismatch", now_utime, outcome);
    else Reject(RejectReason::kFeStepFailed, r.error, now_utime, outcome);
    return false;
  }
  ++counters_.steps;
  ++window_steps_;
  field_.utime = now_utime;
  field_.source_scan_utime = scan.utime;
  Eigen::Map<Eigen::VectorXd>(field_.sed_Pa.data(), r.sed_Pa->size()) = *r.sed_Pa;
  outcome->max_sed_Pa = display::MaxFiniteSed(field_);
  return true;
}

void BridgePipeline::SendToDisplay(int64_t now_utime, int64_t receive_wall_utime, ScanOutcome* outcome) {
  const display::DisplayCommand& c = display_->OnSedField(field_, now_utime);
  outcome->stage_ms.Add(display_->last_stage_ms());
  outcome->latency_us = wall_clock_() - receive_wall_utime;
  latency_.Add(outcome->latency_us);
  ++counters_.commands;
  ++window_commands_;
  outcome->max_command = c.value.empty() ? 0 : *std::max_element(c.value.begin(), c.value.end());
  outcome->stepped = true;
}

void BridgePipeline::PublishContact(int64_t now_utime, ScanOutcome* outcome) {
  // After the command, so the contact report stays out of the scan-to-command latency.
  const contact::ContactReport* report = fe_->contact_report();
  if (!report) return;
  const StageTimer timer(outcome->stage_ms, Stage::kPublish);
  if (report->estimate.model_inadequate) ++model_inadequate_scans_;
  lcmt_contact_estimate msg = lcm_io::ToLcm(*report);
  msg.utime = now_utime;
  display_->publisher().Publish(display_->publisher().channels().contact, msg);
}

void BridgePipeline::PublishRendering(int64_t now_utime) {
  // A viewer's message: after the command (outside its latency), decimated, in no stage time;
  // the renderer's own evaluation at its answer, so it costs a copy, not an SED evaluation.
  if (!predicted_sed_ || !(config_.rendering_Hz > 0)) return;
  const bool due = !rendering_published_ || now_utime < last_rendering_utime_ ||
                   now_utime - last_rendering_utime_ >= 1e6 / config_.rendering_Hz;
  if (!due) return;
  const display::DisplayCommand& c = display_->last_command();
  predicted_sed_(&delivered_Pa_, &rendered_);
  if (std::size_t(delivered_Pa_.size()) != field_.sed_Pa.size()) return;
  rendering_published_ = true;
  last_rendering_utime_ = now_utime;
  lcmt_display_rendering m;
  m.utime = c.utime;
  m.command_sequence = c.sequence;
  m.source_scan_utime = field_.source_scan_utime;
  m.display_id = c.display_id;
  m.model_id = field_.model_id;
  m.num_vertices = int32_t(field_.sed_Pa.size());
  m.target_sed_Pa.resize(field_.sed_Pa.size());
  m.delivered_sed_Pa.resize(field_.sed_Pa.size());
  m.max_target_sed_Pa = m.max_delivered_sed_Pa = 0;
  for (std::size_t v = 0; v < field_.sed_Pa.size(); ++v) {
    // The renderer's target: negative SED read as 0 (InverseDisplayRequests::Request).
    const double target = std::isfinite(field_.sed_Pa[v]) ? std::max(field_.sed_Pa[v], 0.0) : field_.sed_Pa[v];
    m.target_sed_Pa[v] = lcm_io::ToLcmFloat(target);
    m.delivered_sed_Pa[v] = lcm_io::ToLcmFloat(delivered_Pa_[Eigen::Index(v)]);
    if (std::isfinite(m.target_sed_Pa[v])) m.max_target_sed_Pa = std::max(m.max_target_sed_Pa, m.target_sed_Pa[v]);
    if (std::isfinite(m.delivered_sed_Pa[v]))
      m.max_delivered_sed_Pa = std::max(m.max_delivered_sed_Pa, m.delivered_sed_Pa[v]);
  }
  m.limited = rendered_.size() != c.value.size() || !std::equal(rendered_.begin(), rendered_.end(), c.value.begin());
  display_->publisher().Publish(display_->publisher().channels().rendering, m);
}

void BridgePipeline::RecordStageTimes(const StageTimes& stage_ms) {
  // Per stage over the scans that ran it (a contact step presses only when there is contact).
  for (int i = 0; i < kNumStages; ++i)
    if (stage_ms.ms[size_t(i)] > 0) stage_stats_[size_t(i)].AddMs(stage_ms.ms[size_t(i)]);
}

void BridgePipeline::Tick(int64_t now_utime) {
  if (shut_down_) return;
  if (window_start_utime_ < 0) window_start_utime_ = now_utime;
  display_->Tick(now_utime);
  ++counters_.commands;
  ++window_commands_;
  MaybePublishStatus(now_utime);
}

void BridgePipeline::Shutdown(int64_t now_utime) {
  if (shut_down_) return;
  shut_down_ = true;
  display_->Shutdown(now_utime);
  counters_.commands += lcm_io::DisplaySession::kShutdownRepeats;
  display_->publisher().Publish(display_->publisher().channels().status, MakeStatus(now_utime));
  ++counters_.status_messages;
  if (auto* log = display_->publisher().log()) log->Flush();
}

void BridgePipeline::SetSensorCounters(const sensors::BadFrameCounters& counters,
                                       const sensors::FrameSourceStats& source) {
  sensor_counters_ = counters;
  source_stats_ = source;
}

void BridgePipeline::MaybePublishStatus(int64_t now_utime) {
  if (now_utime - window_start_utime_ < status_period_us_) return;
  const double seconds = static_cast<double>(now_utime - window_start_utime_) * 1e-6;
  window_rates_[0] = window_scans_ / seconds;
  window_rates_[1] = window_steps_ / seconds;
  window_rates_[2] = window_commands_ / seconds;
  window_latency_ = latency_.Window();
  for (int i = 0; i < kNumStages; ++i) {
    window_stage_p50_ms_.ms[size_t(i)] = stage_stats_[size_t(i)].Window().p50_ms;
    stage_stats_[size_t(i)].ResetWindow();
  }
  // Degraded (not a fault): invalid taxels filled, scans dropped upstream, taxels off the pad.
  if (fault_state_ != FaultState::kFault) {
    fault_state_ = FaultState::kOk;
    fault_message_.clear();
    if (window_invalid_ > 0)
      fault_state_ = FaultState::kDegraded, fault_message_ = std::to_string(window_invalid_) + " invalid taxel readings";
    // Said, not hidden: taxel_health[] has each taxel's state; the message names them too.
    if (health_.masked_count() > 0) fault_state_ = FaultState::kDegraded, fault_message_ += (fault_message_.empty() ? "" : "; ") + health_.Summary();
  }
  display_->publisher().Publish(display_->publisher().channels().status, MakeStatus(now_utime));
  ++counters_.status_messages;
  latency_.ResetWindow();
  window_start_utime_ = now_utime;
  window_scans_ = window_steps_ = window_commands_ = window_invalid_ = 0;
}

StageTimes BridgePipeline::RunStageMedians_ms() const {
  StageTimes p50;
  for (int i = 0; i < kNumStages; ++i) p50.ms[size_t(i)] = stage_stats_[size_t(i)].Run().p50_ms;
  return p50;
}

lcmt_bridge_status BridgePipeline::MakeStatus(int64_t now_utime) const {
  lcmt_bridge_status s{};
  s.utime = now_utime;
  s.scan_rate_Hz = static_cast<float>(window_rates_[0]);
  s.step_rate_Hz = static_cast<float>(window_rates_[1]);
  s.command_rate_Hz = static_cast<float>(window_rates_[2]);
  s.latency_p50_ms = static_cast<float>(window_latency_.p50_ms);
  s.latency_p90_ms = static_cast<float>(window_latency_.p90_ms);
  s.latency_p99_ms = static_cast<float>(window_latency_.p99_ms);
  s.latency_max_ms = static_cast<float>(window_latency_.max_ms);
  s.solver_iterations = last_report_.linear_iterations;
  s.solver_residual = static_cast<float>(last_report_.linear_residual);
  s.scans_received = counters_.scans;
  s.scans_dropped = dropped_upstream_ + sensor_counters_.scans_dropped + counters_.scans_rejected;
  s.num_reject_reasons = static_cast<int8_t>(kNumRejectReasons);
  for (const auto& [reason, name] : NamesOf(RejectReason{})) {
    s.reject_reason.push_back(name);
    s.scans_rejected.push_back(counters_.rejected_by_reason[reason]);
  }
  // The message predates BadFrameCounters; map its three buckets (see config/bridge/README.md).
  const sensors::BadFrameCounters& b = sensor_counters_;
  s.bad_frames_length = b.wrong_length + b.wrong_frame_type;
  s.bad_frames_checksum = b.error_frames + b.bad_frame_index + b.remote_frames;
  s.bad_frames_sequence = b.missing_frames + b.stale_frames + b.duplicates;
  const display::DisplayStats& d = const_cast<lcm_io::DisplaySession&>(*display_).controller().stats();
  s.commands_clamped = d.commands_clamped;
  s.commands_stale = d.commands_stale;
  s.commands_fault = d.commands_fault;
  const FaultState state = shut_down_ ? FaultState::kFault : fault_state_;
  s.fault_message = shut_down_ ? "shut down" : fault_message_;
  // The CAN controller's own state: bus-off is a fault (no scans can arrive), error-passive
  // degraded (the bus is failing). Reported while it lasts.
  const FaultState bus = b.bus_state == sensors::kBusOff           ? FaultState::kFault
                         : b.bus_state == sensors::kBusErrorPassive ? FaultState::kDegraded
                                                                    : FaultState::kOk;
  const bool bus_worse = !shut_down_ && static_cast<int8_t>(bus) > static_cast<int8_t>(state);
  s.fault_state = static_cast<int8_t>(bus_worse ? bus : state);
  if (bus_worse) s.fault_message = bus == FaultState::kFault ? "CAN bus-off" : "CAN error-passive";
  // Median wall time per stage over the window's stepped scans that ran it [ms].
  const StageTimes& p50 = window_stage_p50_ms_;
  s.conditioning_p50_ms = static_cast<float>(p50[Stage::kConditioning]);
  s.boundary_condition_p50_ms = static_cast<float>(p50[Stage::kBoundaryCondition]);
  s.assembly_p50_ms = static_cast<float>(p50[Stage::kAssembly]);
  s.solve_p50_ms = static_cast<float>(p50[Stage::kSolve]);
  s.sed_p50_ms = static_cast<float>(p50[Stage::kSed]);
  s.reconstruction_p50_ms = static_cast<float>(p50[Stage::kReconstruction]);
  s.press_p50_ms = static_cast<float>(p50[Stage::kPress]);
  s.limiter_p50_ms = static_cast<float>(p50[Stage::kLimiter]);
  s.publish_p50_ms = static_cast<float>(p50[Stage::kPublish]);
  lcm_io::SetTaxelHealth(health_, &s);
  s.model_inadequate_scans = model_inadequate_scans_;
  return s;
}

}  // namespace sedbridge::bridge
