#include "bridge/contact_fe_step.h"

#include <cstdio>
#include <stdexcept>
#include <string>

#include "bridge/scene_fe_step.h"
#include "common/thread_cpu_time.h"
#include "model/fingertip_model.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::bridge {
namespace {

// A primitive from the sensor's pad frame into the leader's, by the registration.
contact::ToLeaderPad LeaderPadOf(const PadRegistration& registration) {
  return [registration](sensors::ContactPrimitive& p) {
    const Eigen::Vector2d xy = registration.ToPad(Eigen::Vector2d(p.x_mm, p.y_mm));
    const Eigen::Vector2d shear = registration.RotateToPad(Eigen::Vector2d(p.shear_x_N, p.shear_y_N));
    p.x_mm = xy.x();
    p.y_mm = xy.y();
    p.radius_mm *= registration.params().scale;
    p.length_mm *= registration.params().scale;
    p.yaw_deg += registration.params().rotation_deg;
    p.shear_x_N = shear.x();
    p.shear_y_N = shear.y();
  };
}

// Thread CPU time from construction to destruction into `stats`.
struct CpuTimer {
  LatencyStats* stats;
  double start_ms = ThreadCpuTime_ms();
  ~CpuTimer() { stats->AddMs(ThreadCpuTime_ms() - start_ms); }
};

}  // namespace

ContactFeStep::ContactFeStep(const std::string& model_name, const sensors::SensorProfile& profile,
                             const PadRegistration& registration, std::unique_ptr<FeStep> fallback,
                             scene::FingertipComplianceOptions leader, contact::ReconstructionOptions options,
                             scene::PressToForceOptions press, const model::MerkelVertexFilter& merkel_filter,
                             std::shared_ptr<const model::FingertipModel> model)
    : model_(std::move(model)), fallback_(std::move(fallback)) {
  if (!model_) model_ = std::make_shared<const model::FingertipModel>(LoadBridgeModel(model_name, merkel_filter));
  stage_ = std::make_unique<contact::ContactStage>(*model_, profile, LeaderPadOf(registration), std::move(leader),
                                                   options, press);
  const int vertices = int(stage_->leader().merkel_rest_pad_mm().cols());
  zero_sed_ = Eigen::VectorXd::Zero(vertices);
  // The fallback answers some scans: its SED must be over the same vertices.
  if (fallback_->merkel_rest_pad_mm().cols() != vertices)
    throw std::invalid_argument("contact FE step: the fallback's Merkel layer has " +
                                std::to_string(fallback_->merkel_rest_pad_mm().cols()) + " vertices, the leader's " +
                                std::to_string(vertices));
}

ContactFeStep::~ContactFeStep() = default;

std::shared_ptr<const fem::ComplianceOperator> ContactFeStep::leader_operator() const {
  return stage_->leader().contact().shared_operator();
}

const Eigen::Matrix3Xd& ContactFeStep::merkel_rest_pad_mm() const { return stage_->leader().merkel_rest_pad_mm(); }

std::string ContactFeStep::Describe() const {
  const int nodes = int(stage_->leader().contact().candidate_nodes().size());
  const int faces = stage_->leader().contact().num_samples() - nodes;
  return "contact reconstruction -> compliance press on " + model_id() + " (" + std::to_string(nodes) +
         " candidate nodes" + (faces > 0 ? " + " + std::to_string(faces) + " face points" : std::string()) +
         "), fallback: " + fallback_->Describe();
}

bool ContactFeStep::Frame(FeFrame* frame) const {
  Eigen::VectorXd x = stage_->leader().contact().full_positions_m();
  if (x.size() == 0) return false;  // built without full_field
  if (last_ == LastStep::kFallback && fallback_->Frame(frame)) return true;
  const fem::TetMesh& mesh = model_->soft;
  if (last_ == LastStep::kNone) x = Eigen::Map<const Eigen::VectorXd>(mesh.rest_positions_m.data(), mesh.rest_positions_m.size());
  frame->mesh = &mesh;
  frame->positions_m = std::move(x);
  const Eigen::VectorXd& sed = result_.ok && result_.sed_Pa ? *result_.sed_Pa : zero_sed_;
  frame->point_fields = {MerkelSedPointField(mesh.num_nodes(), model_->merkel_nodes, sed)};
  return true;
}

std::string ContactFeStep::CountersLine() const {
  const auto& r = stage_->reconstructor().counters();
  const contact::ContactStepCounters& c = stage_->counters();
  const LatencySummary rt = recon_time_.Run(), pt = press_time_.Run(), ct = cpu_time_.Run();
  char line[1000];
  std::snprintf(line, sizeof line,
                "contact: %lld scans pressed on the leader (%lld reusing the last press; %lld fits of two contacts), "
                "%lld no contact, "
                "%lld fit fallbacks, %lld press fallbacks "
                "(pressure map; %lld not tried again), %lld pressed thicker (too thin for the leader); %lld presses by one force-controlled solve, %lld contact solves; "
                "%lld of %lld fits warm-started, %lld forward-model "
                "evaluations; reconstruction median %.3f / p99 %.3f ms, "
                "leader press median %.3f / p99 %.3f ms; CPU per scan median %.3f / p99 %.3f ms",
                static_cast<long long>(c.pressed), static_cast<long long>(c.press_reused),
                static_cast<long long>(r.two_contacts), static_cast<long long>(c.no_contact),
                static_cast<long long>(c.fit_fallbacks), static_cast<long long>(c.press_fallbacks),
                static_cast<long long>(c.press_known_unreachable), static_cast<long long>(c.press_thickened), static_cast<long long>(c.force_controlled), static_cast<long long>(c.press_solves),
                static_cast<long long>(r.warm_fits), static_cast<long long>(r.fits),
                static_cast<long long>(r.evaluations), rt.p50_ms, rt.p99_ms, pt.p50_ms,
                pt.p99_ms, ct.p50_ms, ct.p99_ms);
  if (surface_)
    return std::string(line) + "; " + std::to_string(surface_answers_) +
           " answered by the surface pressure (fe.fallback)";
  return line;
}

scene::PressToForceOptions ReconstructedPressOptions(const BridgeConfig& config) {
  scene::PressToForceOptions options = contact::ReconstructedPressOptions();
  options.contact_relative_tolerance = config.contact_tolerance;
  return options;
}

contact::ReconstructionOptions ReconstructionOptionsOf(const BridgeConfig& config) {
  contact::ReconstructionOptions options;
  options.fit_pairs = config.two_contacts;
  options.fit_finite_rods = config.finite_rods;
  options.radius_track_posterior = config.radius_tracking == RadiusTracking::kPosterior;
  return options;
}

const MerkelSedResult& ContactFeStep::Step(const TaxelValues& values) {
  StageTimes times;
  if (!values.scan) return Answer(stage_->NoScan(values.scan_utime), values, times);
  const CpuTimer cpu_timer{&cpu_time_};  // everything below, the fallback's step included
  const contact::ContactStepOutcome outcome = stage_->Step(*values.scan, values.scan_utime, times);
  RecordStageTimes(outcome, times);
  return Answer(outcome, values, times);
}

void ContactFeStep::RecordStageTimes(const contact::ContactStepOutcome& outcome, const StageTimes& times) {
  if (outcome.reconstructed) recon_time_.AddMs(times[Stage::kReconstruction]);
  if (outcome.press_solved) press_time_.AddMs(times[Stage::kPress]);
}

const MerkelSedResult& ContactFeStep::Answer(const contact::ContactStepOutcome& outcome, const TaxelValues& values,
                                             const StageTimes& times) {
  switch (outcome.answer) {
    case contact::ContactAnswer::kNoContact:
      last_ = LastStep::kNone;
      result_ = MerkelSedResult{};
      result_.ok = true;
      result_.sed_Pa = &zero_sed_;
      result_.report.stage_ms = times;
      return result_;
    case contact::ContactAnswer::kPressed:
      if (surface_for_flagged_ && stage_->report().estimate.model_inadequate) return SurfacePressure(values, times);
      last_ = LastStep::kPressed;
      result_ = MerkelSedResult{};
      result_.ok = true;
      result_.sed_Pa = &stage_->sed_Pa();
      result_.applied_force_N = outcome.force_N;
      result_.report.converged = true;
      result_.report.newton_iterations = outcome.press_iterations;
      result_.report.stage_ms = times;
      return result_;
    case contact::ContactAnswer::kFallback: break;
  }
  if (surface_ && values.scan) return SurfacePressure(values, times);
  last_ = LastStep::kFallback;
  return Fallback(values, times);
}

void ContactFeStep::UseSurfacePressure(const sensors::SensorProfile& profile, const PadRegistration& registration,
                                       const sensors::SurfacePressureOptions& options, bool flagged_too) {
  surface_ = std::make_unique<sensors::SurfacePressureInversion>(profile, options);
  Eigen::Matrix2Xd cells(2, surface_->cell_count());
  for (int c = 0; c < surface_->cell_count(); ++c) cells.col(c) = registration.ToPad(surface_->CellCentre_mm(c));
  surface_on_leader_ = std::make_unique<contact::SurfacePressureOnLeader>(
      stage_->LeaderForOtherLoad(), cells, surface_->cell_mm() * registration.params().scale);
  surface_rotation_.col(0) = registration.RotateToPad(Eigen::Vector2d::UnitX());
  surface_rotation_.col(1) = registration.RotateToPad(Eigen::Vector2d::UnitY());
  surface_for_flagged_ = flagged_too;
}

const MerkelSedResult& ContactFeStep::SurfacePressure(const TaxelValues& values, const StageTimes& times) {
  const sensors::SurfacePressure& p = surface_->Solve(*values.scan);
  if (!p.ok || !surface_on_leader_->Press(p.cell_force_N, surface_rotation_ * p.shear_N)) {
    last_ = LastStep::kFallback;
    return Fallback(values, times);
  }
  stage_->LeaderForOtherLoad();  // the press it held is gone: not reused by the next scan
  ++surface_answers_;
  last_ = LastStep::kPressed;
  result_ = MerkelSedResult{};
  result_.ok = true;
  result_.sed_Pa = &stage_->sed_Pa();
  result_.applied_force_N = surface_on_leader_->applied_force_N();
  result_.report.converged = true;
  result_.report.stage_ms = times;
  return result_;
}

const MerkelSedResult& ContactFeStep::Fallback(const TaxelValues& values, const StageTimes& times) {
  result_ = fallback_->Step(values);  // its sed_Pa stays valid until the fallback's next step
  result_.report.stage_ms.Add(times);
  return result_;
}

}  // namespace sedbridge::bridge
