#pragma once
// FeStep by contact reconstruction (bridge config `fe.step: contact`): each scan's contact
// is reconstructed through the follower sensor's forward model (contact_reconstruction.h),
// registered into the leader's pad frame, and the object is pressed onto the leader's
// fingertip model with the paper's penalty contact by the compliance method
// (scene::FingertipCompliance::PressToForce), force-matched to the sensor's estimate and
// carrying its tangential force. The contact pressure on the leader's pad then comes from
// the leader's own pad mechanics, not from the taxels.
//
// No contact -> zero SED without a solve. A fit that falls back, or a press that cannot
// reach the force (object beyond the pad's patch), uses the pressure-map step (`fallback`),
// and is counted.

#include <memory>
#include <string>

#include "bridge/bridge_config.h"
#include "bridge/fe_step.h"
#include "bridge/latency_stats.h"
#include "bridge/pad_registration.h"
#include "contact/contact_object.h"
#include "contact/contact_reconstruction.h"
#include "model/fingertip_model.h"

namespace sedbridge::scene {
class FingertipCompliance;
}

namespace sedbridge::bridge {

// The contact stage's names the bridge speaks (src/contact/).
using contact::ContactEstimate;
using contact::ContactReconstructor;
using contact::kLeaderMinRodRadius_mm;
using contact::kLeaderMinSphereRadius_mm;
using contact::LeaderComplianceOptions;
using contact::LeaderPress;
using contact::LeaderTangentialLoad_N;
using contact::ModelSelection;
using contact::PressAnswered;
using contact::PressReconstructed;
using contact::ReconstructedPressOptions;
using contact::ReconstructionOptions;
using contact::ToRigidObject;
using contact::ToRigidObjects;

/// The leader press's options with the config's fe.contact_tolerance as its contact tolerance.
scene::PressToForceOptions ReconstructedPressOptions(const BridgeConfig& config);
/// The reconstruction of fe.step contact as a config sets it (fe.two_contacts,
/// fe.finite_rods, fe.radius_tracking): one place for the bridge (MakeFeStep) and the fidelity benchmark.
ReconstructionOptions ReconstructionOptionsOf(const BridgeConfig& config);

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

class ContactFeStep final : public FeStep {
 public:
  /// @param model_name  leader fingertip model (linear, bone fixed: the compliance method)
  /// @param profile     three-axis sensor profile with a forward_model
  /// @param registration  sensor pad -> leader pad frame
  /// @param fallback    pressure-map step for scans the reconstruction cannot explain
  /// @param leader      the leader press's options: LeaderComplianceOptions(cache dir, face
  ///                    contact); contact.full_field keeps what frame_positions_m() needs
  ///                    for the whole mesh (VTU frames; 24 MB on B, and the precompute runs
  ///                    instead of the cache)
  /// @param press       the leader press's force and contact tolerances
  ///                    (ReconstructedPressOptions(); fe.contact_tolerance sets its contact one)
  /// @param merkel_filter the Merkel vertices whose SED is computed (empty = the whole
  ///                    layer); the fallback must have been built with the same
  ContactFeStep(const std::string& model_name, const sensors::SensorProfile& profile,
                const PadRegistration& registration, std::unique_ptr<FeStep> fallback,
                scene::FingertipComplianceOptions leader, ReconstructionOptions options = {},
                scene::PressToForceOptions press = ReconstructedPressOptions(),
                const model::MerkelVertexFilter& merkel_filter = {});
  ~ContactFeStep() override;

  /// Needs values.scan (set by ScanConditioner); without it the fallback answers.
  const MerkelSedResult& Step(const TaxelValues& values) override;
  const Eigen::Matrix3Xd& merkel_rest_pad_mm() const override;
  const std::string& model_id() const override { return fallback_->model_id(); }
  std::string Describe() const override;
  std::string CountersLine() const override;
  const lcmt_contact_estimate* contact_message() const override { return &message_; }
  /// The leader press's options (fe.contact_tolerance is their contact tolerance).
  const scene::PressToForceOptions& press_options() const { return press_options_; }
  /// With leader.contact.full_field: the leader's mesh under the pressed object and the step's Merkel SED
  /// (a fallback scan shows the fallback's own frame, or rest). False without full_field.
  bool Frame(FeFrame* frame) const override;

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

  /// The last scan's estimate in the leader's pad frame.
  const ContactEstimate& last_estimate() const { return estimate_; }
  const ContactStepCounters& counters() const { return counters_; }
  const ContactReconstructor& reconstructor() const { return *reconstructor_; }
  /// Wall time per step of the two stages (also in each result's report.stage_ms as
  /// kReconstruction and kPress): reconstruction, and the press on the leader (contact
  /// solves + Merkel SED), over the scans that reached them.
  LatencySummary reconstruction_time() const { return recon_time_.Run(); }
  LatencySummary press_time() const { return press_time_.Run(); }
  /// Thread CPU time per step over the scans that reached the reconstruction (reconstruction
  /// + press + SED, or the fallback's step): the cost without preemption.
  LatencySummary cpu_time() const { return cpu_time_.Run(); }

 private:
  void FillMessage(const TaxelValues& values, bool fallback, double indentation_mm);
  /// The fallback's result with this step's stage times added.
  const MerkelSedResult& Fallback(const TaxelValues& values, const StageTimes& times);

  std::unique_ptr<model::FingertipModel> model_;
  std::unique_ptr<scene::FingertipCompliance> leader_;
  std::unique_ptr<ContactReconstructor> reconstructor_;
  std::unique_ptr<FeStep> fallback_;
  PadRegistration registration_;
  scene::PressToForceOptions press_options_;
  ContactEstimate estimate_;
  ContactStepCounters counters_;
  enum class LastStep { kNone, kPressed, kFallback } last_ = LastStep::kNone;
  /// True when `e` presses the same as the last pressed contact (see set_reuse_press).
  bool SameAsLastPress(const ContactEstimate& e) const;
  bool reuse_press_ = true;
  ContactEstimate last_pressed_;  // pad frame
  /// True when `e` is the object of the last press that could not reach its force, where
  /// that press left it, at a force no lower (see set_skip_known_unreachable).
  bool KnownUnreachable(const ContactEstimate& e) const;
  bool skip_known_unreachable_ = true;
  bool have_unreachable_ = false;
  ContactEstimate last_unreachable_;  // pad frame
  std::string last_unreachable_problem_;
  scene::PressStatus last_unreachable_status_{};
  double unreachable_force_N_ = 0;  // that press's force where it stopped
  double last_force_N_ = 0, last_indentation_mm_ = 0;
  Eigen::VectorXd zero_sed_;
  MerkelSedResult result_;
  lcmt_contact_estimate message_{};
  // Samples kept for the run's percentiles of each stage time [-]: 100k (400 kB) are enough
  // for a p99 of a counters line; the bridge's own latency keeps the default 4M.
  static constexpr int64_t kStageTimeSamples = 100000;
  LatencyStats recon_time_{kStageTimeSamples}, press_time_{kStageTimeSamples}, cpu_time_{kStageTimeSamples};
};

}  // namespace sedbridge::bridge
