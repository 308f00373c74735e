#include "contact/contact_stage.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace sedbridge::contact {
namespace {

// The same pose to 5 um, 0.2 % in radius and length, 0.05 deg in yaw (any flat is the flat).
bool SamePose(const sensors::ContactPrimitive& a, const sensors::ContactPrimitive& b) {
  if (a.shape != b.shape) return false;
  if (a.shape == sensors::ContactShape::kFlat) return true;
  if (a.shape == sensors::ContactShape::kPunch)
    for (int i = 0; i < 2; ++i)
      if (!(std::abs(std::log(a.half_size_mm[i] / b.half_size_mm[i])) <= 2e-3)) return false;
  if ((a.length_mm > 0) != (b.length_mm > 0)) return false;
  if (a.length_mm > 0 && !(std::abs(std::log(a.length_mm / b.length_mm)) <= 2e-3)) return false;
  return std::abs(a.x_mm - b.x_mm) <= 5e-3 && std::abs(a.y_mm - b.y_mm) <= 5e-3 &&
         (a.shape == sensors::ContactShape::kPunch || a.shape == sensors::ContactShape::kCorner ||
          std::abs(std::log(a.radius_mm / b.radius_mm)) <= 2e-3) &&
         std::abs(std::remainder(a.yaw_deg - b.yaw_deg, 180.0)) <= 0.05;
}

bool SamePoses(const ContactEstimate& a, const ContactEstimate& b) {
  // A pair shares its force between the spheres by where they sit (the leader's mechanics):
  // the same pose of both presses the same.
  return a.two_contacts == b.two_contacts && SamePose(a.primitive, b.primitive) &&
         (!a.two_contacts || SamePose(a.second, b.second));
}

}  // namespace

ContactStage::ContactStage(const model::FingertipModel& leader_model, const sensors::SensorProfile& profile,
                           ToLeaderPad to_pad, scene::FingertipComplianceOptions leader, ReconstructionOptions options,
                           scene::PressToForceOptions press)
    : to_pad_(std::move(to_pad)), press_options_(press) {
  reconstructor_ = std::make_unique<ContactReconstructor>(profile, options);
  leader_ = std::make_unique<scene::FingertipCompliance>(leader_model, std::move(leader));
}

ContactStage::~ContactStage() = default;

ContactStepOutcome ContactStage::NoScan(int64_t scan_utime) {
  ++counters_.steps;
  report_.scan_utime = scan_utime;
  report_.estimate = ContactEstimate{};
  Report(true, 0);
  last_pressed_valid_ = false;
  return ContactStepOutcome{};
}

ContactStepOutcome ContactStage::Step(const sensors::Scan& scan, int64_t scan_utime, StageTimes& times) {
  ++counters_.steps;
  report_.scan_utime = scan_utime;
  Reconstruct(scan, times);
  ContactStepOutcome outcome = Answer(times);
  outcome.reconstructed = true;
  return outcome;
}

ContactStepOutcome ContactStage::Answer(StageTimes& times) {
  const ContactEstimate& e = report_.estimate;
  if (e.ok && (!e.contact || Negligible())) return NoContact();
  if (!e.ok) return FitFallback();
  if (reuse_press_ && last_pressed_valid_ && SameAsLastPress(e)) return ReusePress();
  if (skip_known_unreachable_ && KnownUnreachable(e)) return DeclineUnreachable();
  return Press(times);
}

void ContactStage::Reconstruct(const sensors::Scan& scan, StageTimes& times) {
  StageTimer timer(times, Stage::kReconstruction);
  report_.estimate = reconstructor_->Reconstruct(scan);
  timer.Stop();
  to_pad_(report_.estimate.primitive);
  if (report_.estimate.two_contacts) to_pad_(report_.estimate.second);
}

bool ContactStage::Negligible() const {
  // A fit whose force is a tenth of the no-contact threshold or less (the readings' sum
  // passed the threshold, the fitted object presses far less: a touch's first scans) is no
  // contact too: pressing the leader to ~0 N only collapses the root find's bracket (a press
  // fallback on a two-sphere make-log scene, 0.00005 N at its first touch).
  const ContactEstimate& e = report_.estimate;
  return e.contact && e.normal_force_N() < 0.1 * reconstructor_->options().min_force_N;
}

ContactStepOutcome ContactStage::NoContact() {
  ++counters_.no_contact;
  have_unreachable_ = false;
  leader_->ResetWarmStart();
  Report(false, 0);
  last_pressed_valid_ = false;
  ContactStepOutcome outcome;
  outcome.answer = ContactAnswer::kNoContact;
  return outcome;
}

ContactStepOutcome ContactStage::FitFallback() {
  ++counters_.fit_fallbacks;
  Report(true, 0);
  last_pressed_valid_ = false;
  return ContactStepOutcome{};
}

ContactStepOutcome ContactStage::ReusePress() {
  Report(false, last_indentation_mm_);
  ++counters_.pressed;
  ++counters_.press_reused;
  ContactStepOutcome outcome;
  outcome.answer = ContactAnswer::kPressed;
  outcome.force_N = last_force_N_;
  outcome.press_iterations = 0;
  return outcome;
}

ContactStepOutcome ContactStage::DeclineUnreachable() {
  ++counters_.press_fallbacks;
  ++counters_.press_known_unreachable;
  report_.estimate.ok = false;
  report_.estimate.problem = last_unreachable_problem_ + " (not pressed again: the same object, no less force)";
  Report(true, 0);
  last_pressed_valid_ = false;
  return ContactStepOutcome{};
}

ContactStepOutcome ContactStage::Press(StageTimes& times) {
  ContactEstimate& e = report_.estimate;
  StageTimer timer(times, Stage::kPress);
  const LeaderPress pressed = PressReconstructed(*leader_, e, press_options_, LeaderTangentialLoad_N(e));
  const scene::PressToForceResult& press = pressed.result;
  timer.Stop();
  ContactStepOutcome outcome;
  outcome.press_solved = true;
  if (pressed.thickened_radius_mm > 0) ++counters_.press_thickened;
  counters_.press_solves += press.iterations;
  if (press.force_controlled) ++counters_.force_controlled;
  have_unreachable_ = false;
  if (!PressAnswered(press, *leader_)) {
    ++counters_.press_fallbacks;
    const bool unreachable = press.status == scene::PressStatus::kNoContact ||
                             press.status == scene::PressStatus::kPatchEdge ||
                             press.status == scene::PressStatus::kMaxDepth;
    if (unreachable) RememberUnreachable(pressed);
    e.ok = false;
    e.problem = std::string("leader press: ") + scene::ToString(press.status) + ": " + press.message;
    if (unreachable) last_unreachable_problem_ = e.problem;
    Report(true, 0);
    last_pressed_valid_ = false;
    return outcome;
  }
  Report(false, press.indentation_mm);
  ++counters_.pressed;
  last_pressed_valid_ = true;
  last_pressed_ = e;
  last_force_N_ = press.force_N;
  last_indentation_mm_ = press.indentation_mm;
  outcome.answer = ContactAnswer::kPressed;
  outcome.force_N = press.force_N;
  outcome.press_iterations = press.iterations;
  return outcome;
}

void ContactStage::RememberUnreachable(const LeaderPress& pressed) {
  const scene::PressToForceResult& press = pressed.result;
  have_unreachable_ = true;
  last_unreachable_ = report_.estimate;
  last_unreachable_status_ = press.status;
  // Where the press stopped (a thickened retry's: the thinner tries stopped at forces
  // not kept, so then the target itself, as a force no lower than it).
  const double target_N = report_.estimate.normal_force_N();
  unreachable_force_N_ =
      pressed.presses == 1 && std::isfinite(press.force_N) ? std::clamp(press.force_N, 0.0, target_N) : target_N;
}

void ContactStage::Report(bool fallback, double indentation_mm) {
  report_.fallback = fallback;
  report_.indentation_mm = indentation_mm;
}

bool ContactStage::SameAsLastPress(const ContactEstimate& e) const {
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

bool ContactStage::KnownUnreachable(const ContactEstimate& e) const {
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

}  // namespace sedbridge::contact
