#include "bridge/contact_fe_step.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <stdexcept>
#include <string>

#include "bridge/reduced_linear_fe_step.h"
#include "bridge/scene_fe_step.h"
#include "common/thread_cpu_time.h"
#include "model/fingertip_model.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::bridge {

ContactFeStep::ContactFeStep(const std::string& model_name, const sensors::SensorProfile& profile,
                             const PadRegistration& registration, std::unique_ptr<FeStep> fallback,
                             scene::FingertipComplianceOptions leader, ReconstructionOptions options,
                             scene::PressToForceOptions press, const model::MerkelVertexFilter& merkel_filter)
    : fallback_(std::move(fallback)), registration_(registration), press_options_(press) {
  reconstructor_ = std::make_unique<ContactReconstructor>(profile, options);
  model_ = std::make_unique<model::FingertipModel>(LoadBridgeModel(model_name, merkel_filter));
  leader_ = std::make_unique<scene::FingertipCompliance>(*model_, std::move(leader));
  zero_sed_ = Eigen::VectorXd::Zero(leader_->merkel_rest_pad_mm().cols());
  // The fallback answers some scans: its SED must be over the same vertices.
  if (fallback_->merkel_rest_pad_mm().cols() != leader_->merkel_rest_pad_mm().cols())
    throw std::invalid_argument("contact FE step: the fallback's Merkel layer has " +
                                std::to_string(fallback_->merkel_rest_pad_mm().cols()) + " vertices, the leader's " +
                                std::to_string(leader_->merkel_rest_pad_mm().cols()));
}

ContactFeStep::~ContactFeStep() = default;

const Eigen::Matrix3Xd& ContactFeStep::merkel_rest_pad_mm() const { return leader_->merkel_rest_pad_mm(); }

std::string ContactFeStep::Describe() const {
  const int nodes = int(leader_->contact().candidate_nodes().size());
  const int faces = leader_->contact().num_samples() - nodes;
  return "contact reconstruction -> compliance press on " + model_id() + " (" + std::to_string(nodes) +
         " candidate nodes" + (faces > 0 ? " + " + std::to_string(faces) + " face points" : std::string()) +
         "), fallback: " + fallback_->Describe();
}

bool ContactFeStep::Frame(FeFrame* frame) const {
  Eigen::VectorXd x = leader_->contact().full_positions_m();
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
  const auto& r = reconstructor_->counters();
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
                static_cast<long long>(counters_.pressed), static_cast<long long>(counters_.press_reused),
                static_cast<long long>(r.two_contacts), static_cast<long long>(counters_.no_contact),
                static_cast<long long>(counters_.fit_fallbacks), static_cast<long long>(counters_.press_fallbacks),
                static_cast<long long>(counters_.press_known_unreachable), static_cast<long long>(counters_.press_thickened), static_cast<long long>(counters_.force_controlled), static_cast<long long>(counters_.press_solves),
                static_cast<long long>(r.warm_fits), static_cast<long long>(r.fits),
                static_cast<long long>(r.evaluations), rt.p50_ms, rt.p99_ms, pt.p50_ms,
                pt.p99_ms, ct.p50_ms, ct.p99_ms);
  return line;
}

void ContactFeStep::FillMessage(const TaxelValues& values, bool fallback, double indentation_mm) {
  const sensors::ContactPrimitive& p = estimate_.primitive;
  message_ = lcmt_contact_estimate{};
  message_.utime = values.scan_utime;
  message_.source_scan_utime = values.scan_utime;
  message_.shape = !estimate_.contact                       ? 0
                   : estimate_.two_contacts                   ? 4
                   : p.shape == sensors::ContactShape::kSphere   ? 1
                   : p.shape == sensors::ContactShape::kCylinder ? 2
                                                                 : 3;
  message_.x_mm = static_cast<float>(p.x_mm);
  message_.y_mm = static_cast<float>(p.y_mm);
  message_.radius_mm = static_cast<float>(p.radius_mm);
  message_.yaw_deg = static_cast<float>(p.yaw_deg);
  message_.length_mm = static_cast<float>(p.length_mm);
  message_.normal_force_N = static_cast<float>(p.normal_force_N);
  message_.shear_x_N = static_cast<float>(p.shear_x_N);
  message_.shear_y_N = static_cast<float>(p.shear_y_N);
  if (estimate_.two_contacts) {
    const sensors::ContactPrimitive& q = estimate_.second;
    message_.x2_mm = static_cast<float>(q.x_mm);
    message_.y2_mm = static_cast<float>(q.y_mm);
    message_.radius2_mm = static_cast<float>(q.radius_mm);
    message_.normal_force2_N = static_cast<float>(q.normal_force_N);
  }
  message_.residual_rms_sigma = static_cast<float>(estimate_.rms_sigma);
  message_.fallback = fallback ? 1 : 0;
  message_.indentation_mm = static_cast<float>(indentation_mm);
}

scene::PressToForceOptions ReconstructedPressOptions(const BridgeConfig& config) {
  scene::PressToForceOptions options = ReconstructedPressOptions();
  options.contact_relative_tolerance = config.contact_tolerance;
  return options;
}

ReconstructionOptions ReconstructionOptionsOf(const BridgeConfig& config) {
  ReconstructionOptions options;
  options.fit_pairs = config.two_contacts;
  options.fit_finite_rods = config.finite_rods;
  options.radius_track_posterior = config.radius_tracking == RadiusTracking::kPosterior;
  return options;
}

const MerkelSedResult& ContactFeStep::Fallback(const TaxelValues& values, const StageTimes& times) {
  result_ = fallback_->Step(values);  // its sed_Pa stays valid until the fallback's next step
  result_.report.stage_ms.Add(times);
  return result_;
}

namespace {
// The same pose to 5 um, 0.2 % in radius and length, 0.05 deg in yaw (any flat is the flat).
bool SamePose(const sensors::ContactPrimitive& a, const sensors::ContactPrimitive& b) {
  if (a.shape != b.shape) return false;
  if (a.shape == sensors::ContactShape::kFlat) return true;
  if ((a.length_mm > 0) != (b.length_mm > 0)) return false;
  if (a.length_mm > 0 && !(std::abs(std::log(a.length_mm / b.length_mm)) <= 2e-3)) return false;
  return std::abs(a.x_mm - b.x_mm) <= 5e-3 && std::abs(a.y_mm - b.y_mm) <= 5e-3 &&
         std::abs(std::log(a.radius_mm / b.radius_mm)) <= 2e-3 &&
         std::abs(std::remainder(a.yaw_deg - b.yaw_deg, 180.0)) <= 0.05;
}

bool SamePoses(const ContactEstimate& a, const ContactEstimate& b) {
  // A pair shares its force between the spheres by where they sit (the leader's mechanics):
  // the same pose of both presses the same.
  return a.two_contacts == b.two_contacts && SamePose(a.primitive, b.primitive) &&
         (!a.two_contacts || SamePose(a.second, b.second));
}
}  // namespace

bool ContactFeStep::SameAsLastPress(const ContactEstimate& e) const {
  const ContactEstimate& last = last_pressed_;
  // Half the press's own force tolerance (the last answer is within the tolerance of its
  // target), 5 um, 0.2 % in radius, 0.05 deg: the reused SED stays within 3e-3 (L2) of a
  // fresh press (test HoldScansReuseTheLastPressWithTheSameAnswer), about the press's own
  // 1e-3 force tolerance times the SED's sensitivity to force.
  const double force_tol_N = 0.5 * press_options_.relative_tolerance * last.normal_force_N();
  // The tangential load the leader was pressed with, not the raw estimate.
  const Eigen::Vector2d dt = LeaderTangentialLoad_N(e) - LeaderTangentialLoad_N(last);
  if (!(std::abs(e.normal_force_N() - last.normal_force_N()) <= force_tol_N) || !(std::abs(dt.x()) <= force_tol_N) ||
      !(std::abs(dt.y()) <= force_tol_N))
    return false;
  return SamePoses(e, last);
}

bool ContactFeStep::KnownUnreachable(const ContactEstimate& e) const {
  if (!have_unreachable_ || !SamePoses(e, last_unreachable_)) return false;
  switch (last_unreachable_status_) {
    // Nothing touches the leader where the object is: at any force.
    case scene::PressStatus::kNoContact: return true;
    // The press ran into the patch's edge or the maximum depth at a force below its target
    // (unreachable_force_N_): a higher force needs a deeper indentation, which runs into them
    // too. (The tangential load is not compared: the edge and the depth are reached by the
    // normal indentation.)
    case scene::PressStatus::kPatchEdge:
    case scene::PressStatus::kMaxDepth: return e.normal_force_N() >= unreachable_force_N_;
    default: return false;
  }
}

const MerkelSedResult& ContactFeStep::Step(const TaxelValues& values) {
  ++counters_.steps;
  StageTimes times;
  if (!values.scan) {
    estimate_ = ContactEstimate{};
    FillMessage(values, true, 0);
    last_ = LastStep::kFallback;
    return Fallback(values, times);
  }
  // Thread CPU time of everything below, on every return.
  struct CpuTimer {
    LatencyStats* stats;
    double start_ms = ThreadCpuTime_ms();
    ~CpuTimer() { stats->AddMs(ThreadCpuTime_ms() - start_ms); }
  } cpu_timer{&cpu_time_};
  StageTimer recon_timer(times, Stage::kReconstruction);
  estimate_ = reconstructor_->Reconstruct(*values.scan);
  recon_timer.Stop();
  recon_time_.AddMs(times[Stage::kReconstruction]);
  // Into the leader's pad frame.
  auto to_pad = [&](sensors::ContactPrimitive& p) {
    const Eigen::Vector2d xy = registration_.ToPad(Eigen::Vector2d(p.x_mm, p.y_mm));
    const Eigen::Vector2d shear = registration_.RotateToPad(Eigen::Vector2d(p.shear_x_N, p.shear_y_N));
    p.x_mm = xy.x();
    p.y_mm = xy.y();
    p.radius_mm *= registration_.params().scale;
    p.length_mm *= registration_.params().scale;
    p.yaw_deg += registration_.params().rotation_deg;
    p.shear_x_N = shear.x();
    p.shear_y_N = shear.y();
  };
  to_pad(estimate_.primitive);
  if (estimate_.two_contacts) to_pad(estimate_.second);

  // A fit whose force is a tenth of the no-contact threshold or less (the readings' sum
  // passed the threshold, the fitted object presses far less: a touch's first scans) is no
  // contact too: pressing the leader to ~0 N only collapses the root find's bracket (a press
  // fallback on a two-sphere make-log scene, 0.00005 N at its first touch).
  const bool negligible = estimate_.ok && estimate_.contact &&
                          estimate_.normal_force_N() < 0.1 * reconstructor_->options().min_force_N;
  if (estimate_.ok && (!estimate_.contact || negligible)) {
    ++counters_.no_contact;
    have_unreachable_ = false;
    leader_->ResetWarmStart();
    result_ = MerkelSedResult{};
    result_.ok = true;
    result_.sed_Pa = &zero_sed_;
    result_.report.stage_ms = times;
    FillMessage(values, false, 0);
    last_ = LastStep::kNone;
    return result_;
  }
  if (!estimate_.ok) {
    ++counters_.fit_fallbacks;
    FillMessage(values, true, 0);
    last_ = LastStep::kFallback;
    return Fallback(values, times);
  }
  if (reuse_press_ && last_ == LastStep::kPressed && SameAsLastPress(estimate_)) {
    FillMessage(values, false, last_indentation_mm_);
    ++counters_.pressed;
    ++counters_.press_reused;
    result_ = MerkelSedResult{};
    result_.ok = true;
    result_.sed_Pa = &leader_->sed_Pa();
    result_.applied_force_N = last_force_N_;
    result_.report.converged = true;
    result_.report.newton_iterations = 0;
    result_.report.stage_ms = times;
    return result_;
  }
  if (skip_known_unreachable_ && KnownUnreachable(estimate_)) {
    ++counters_.press_fallbacks;
    ++counters_.press_known_unreachable;
    estimate_.ok = false;
    estimate_.problem = last_unreachable_problem_ + " (not pressed again: the same object, no less force)";
    FillMessage(values, true, 0);
    last_ = LastStep::kFallback;
    return Fallback(values, times);
  }
  StageTimer press_timer(times, Stage::kPress);
  const LeaderPress pressed = PressReconstructed(*leader_, estimate_, press_options_, LeaderTangentialLoad_N(estimate_));
  const scene::PressToForceResult& press = pressed.result;
  press_timer.Stop();
  if (pressed.thickened_radius_mm > 0) ++counters_.press_thickened;
  press_time_.AddMs(times[Stage::kPress]);
  counters_.press_solves += press.iterations;
  if (press.force_controlled) ++counters_.force_controlled;
  have_unreachable_ = false;
  if (!PressAnswered(press, *leader_)) {
    ++counters_.press_fallbacks;
    const bool unreachable = press.status == scene::PressStatus::kNoContact ||
                             press.status == scene::PressStatus::kPatchEdge ||
                             press.status == scene::PressStatus::kMaxDepth;
    if (unreachable) {
      have_unreachable_ = true;
      last_unreachable_ = estimate_;
      last_unreachable_status_ = press.status;
      // Where the press stopped (a thickened retry's: the thinner tries stopped at forces
      // not kept, so then the target itself, as a force no lower than it).
      const double target_N = estimate_.normal_force_N();
      unreachable_force_N_ =
          pressed.presses == 1 && std::isfinite(press.force_N) ? std::clamp(press.force_N, 0.0, target_N) : target_N;
    }
    estimate_.ok = false;
    estimate_.problem = std::string("leader press: ") + scene::ToString(press.status) + ": " + press.message;
    if (unreachable) last_unreachable_problem_ = estimate_.problem;
    FillMessage(values, true, 0);
    last_ = LastStep::kFallback;
    return Fallback(values, times);
  }
  FillMessage(values, false, press.indentation_mm);
  ++counters_.pressed;
  last_ = LastStep::kPressed;
  last_pressed_ = estimate_;
  last_force_N_ = press.force_N;
  last_indentation_mm_ = press.indentation_mm;
  result_ = MerkelSedResult{};
  result_.ok = true;
  result_.sed_Pa = &leader_->sed_Pa();
  result_.applied_force_N = press.force_N;
  result_.report.converged = true;
  result_.report.newton_iterations = press.iterations;
  result_.report.stage_ms = times;
  return result_;
}

}  // namespace sedbridge::bridge
