#pragma once
// The contact stage: one scan of the follower's sensor in; the contact estimate (leader pad
// frame) and the Merkel-layer SED of the leader's fingertip out.
//
//   reconstruct (contact_reconstruction.h) -> into the leader's pad frame
//   -> no contact: zero SED, no solve
//   -> a fit that falls back: the caller's pressure map answers
//   -> the same contact as the last press: that press's SED
//   -> the object where the last press could not reach its force: the pressure map
//   -> the press on the leader (contact_object.h): its SED, or the pressure map
//
// The leader is the compliance method's fingertip (scene::FingertipCompliance): the object is
// pressed onto it with the paper's penalty contact, force-matched to the sensor's estimate
// and carrying its tangential force, so the pressure on the leader's pad comes from its own
// mechanics, not from the taxels.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "common/stage_times.h"
#include "contact/contact_estimate.h"
#include "contact/contact_object.h"
#include "contact/contact_reconstruction.h"
#include "model/fingertip_model.h"
#include "scene/fingertip_compliance.h"
#include "sensors/scan.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::contact {

struct ContactStepCounters {
  int64_t steps = 0;
  int64_t no_contact = 0;
  int64_t pressed = 0;             ///< answered by the reconstructed contact
  int64_t press_reused = 0;        ///< of those, answered by the last press (same contact)
  int64_t fit_fallbacks = 0;       ///< reconstruction not trusted -> pressure map
  int64_t press_fallbacks = 0;     ///< force not reachable on the leader -> pressure map
  int64_t press_known_unreachable = 0;  ///< of those, not tried again: the same object as the last
                                        ///< press, which could not reach a force no higher
  int64_t press_thickened = 0;     ///< presses of a sphere or rod too thin for the leader at its force,
                                   ///< answered thicker (PressReconstructed)
  int64_t press_solves = 0;        ///< contact solves of the presses that were not reused
  int64_t force_controlled = 0;    ///< presses answered by one force-controlled solve
};

/// What answers a scan.
enum class ContactAnswer {
  kNoContact,  ///< nothing presses: zero SED
  kPressed,    ///< the leader's SED (ContactStage::sed_Pa)
  kFallback,   ///< the caller's pressure-map step
};

/// One scan through the stage.
struct ContactStepOutcome {
  ContactAnswer answer = ContactAnswer::kFallback;
  bool reconstructed = false;  ///< the reconstruction ran (its wall time: Stage::kReconstruction)
  bool press_solved = false;   ///< a leader press ran (its wall time: Stage::kPress)
  double force_N = 0;          ///< kPressed: the force the leader carries [N]
  int press_iterations = 0;    ///< kPressed: contact solves of this scan (0: the last press reused)
};

/// Moves a primitive from the sensor's pad frame into the leader's (position, radius and
/// length, yaw, tangential force): the caller's registration.
using ToLeaderPad = std::function<void(sensors::ContactPrimitive&)>;

class ContactStage {
 public:
  /// @param leader_model  linear, bone fixed (the compliance method); must outlive the stage
  /// @param profile       three-axis sensor profile with a forward_model
  /// @param leader        the leader fingertip's options (LeaderComplianceOptions)
  /// @param press         the leader press's force and contact tolerances (ReconstructedPressOptions)
  ContactStage(const model::FingertipModel& leader_model, const sensors::SensorProfile& profile, ToLeaderPad to_pad,
               scene::FingertipComplianceOptions leader, ReconstructionOptions options, scene::PressToForceOptions press);
  ~ContactStage();

  /// One scan: its estimate into report(), its SED (kPressed) into sed_Pa(); stage wall times
  /// into `times`.
  ContactStepOutcome Step(const sensors::Scan& scan, int64_t scan_utime, StageTimes& times);
  /// A step without a scan: no estimate, the pressure map answers.
  ContactStepOutcome NoScan(int64_t scan_utime);

  /// The last step's estimate (leader pad frame) and how it was answered.
  const ContactReport& report() const { return report_; }
  /// The leader's Merkel SED [Pa] of the last kPressed answer (valid until the next press).
  const Eigen::VectorXd& sed_Pa() const { return leader_->sed_Pa(); }
  const scene::FingertipCompliance& leader() const { return *leader_; }
  /// The leader for another load than a press (a surface pressure's traction field): its
  /// step replaces the last press's SED, so the next scan is not answered by reusing it.
  scene::FingertipCompliance& LeaderForOtherLoad() {
    last_pressed_valid_ = false;
    return *leader_;
  }
  const ContactReconstructor& reconstructor() const { return *reconstructor_; }
  const ContactStepCounters& counters() const { return counters_; }
  const scene::PressToForceOptions& press_options() const { return press_options_; }

  /// Whether a scan whose contact equals the last pressed one (within half the press's force
  /// tolerance, 5 um, 0.2 % in radius, 0.05 deg) reuses that press instead of solving again
  /// (the SED then differs from a fresh press by < 3e-3, L2). On by default; off solves
  /// every scan (tests compare the two).
  void set_reuse_press(bool reuse) { reuse_press_ = reuse; }
  /// Whether a scan whose object is where the last press left it unable to reach its force
  /// (the leader's patch edge or its maximum depth, reached at a force no higher than this
  /// scan's; or no contact at all) falls back at once instead of pressing again, which would
  /// fail the same way (0.5-1 ms a scan at the rig's pad corner, press_11). On by default;
  /// off presses every scan (tests compare the two).
  void set_skip_known_unreachable(bool skip) { skip_known_unreachable_ = skip; }

 private:
  // The stages of Step, in order.
  /// The scan's estimate, into the leader's pad frame.
  void Reconstruct(const sensors::Scan& scan, StageTimes& times);
  /// Who answers the estimate: no contact, the fallback, the last press, or a new press.
  ContactStepOutcome Answer(StageTimes& times);
  /// No contact, or a fit whose force is negligible: zero SED.
  bool Negligible() const;
  ContactStepOutcome NoContact();
  ContactStepOutcome FitFallback();
  ContactStepOutcome ReusePress();
  ContactStepOutcome DeclineUnreachable();
  ContactStepOutcome Press(StageTimes& times);

  /// The report's answer for this scan.
  void Report(bool fallback, double indentation_mm);
  /// True when `e` presses the same as the last pressed contact (see set_reuse_press).
  bool SameAsLastPress(const ContactEstimate& e) const;
  /// True when `e` is the object of the last press that could not reach its force, where
  /// that press left it, at a force no lower (see set_skip_known_unreachable).
  bool KnownUnreachable(const ContactEstimate& e) const;
  /// Remembers a press that could not reach its force (see KnownUnreachable).
  void RememberUnreachable(const LeaderPress& pressed);

  std::unique_ptr<ContactReconstructor> reconstructor_;
  std::unique_ptr<scene::FingertipCompliance> leader_;
  ToLeaderPad to_pad_;
  scene::PressToForceOptions press_options_;
  ContactReport report_;  // its estimate: this scan's, leader pad frame
  ContactStepCounters counters_;
  bool last_pressed_valid_ = false;  // the last step was answered by a press
  bool reuse_press_ = true;
  ContactEstimate last_pressed_;  // pad frame
  bool skip_known_unreachable_ = true;
  bool have_unreachable_ = false;
  ContactEstimate last_unreachable_;  // pad frame
  std::string last_unreachable_problem_;
  scene::PressStatus last_unreachable_status_{};
  double unreachable_force_N_ = 0;  // that press's force where it stopped
  double last_force_N_ = 0, last_indentation_mm_ = 0;
};

}  // namespace sedbridge::contact
