#pragma once
// FeStep by the contact stage (bridge config `fe.step: contact`, src/contact/): each scan's
// contact is reconstructed through the follower sensor's forward model, registered into the
// leader's pad frame, and the object is pressed onto the leader's fingertip model with the
// paper's penalty contact by the compliance method (contact/contact_stage.h).
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
#include "contact/contact_stage.h"
#include "contact/surface_pressure_on_leader.h"
#include "fem/compliance_operator.h"
#include "model/fingertip_model.h"
#include "sensors/surface_pressure_inversion.h"

namespace sedbridge::bridge {

/// The leader press's options with the config's fe.contact_tolerance as its contact tolerance.
scene::PressToForceOptions ReconstructedPressOptions(const BridgeConfig& config);
/// The reconstruction of fe.step contact as a config sets it (fe.two_contacts,
/// fe.finite_rods, fe.radius_tracking): one place for the bridge (MakeFeStep) and the fidelity benchmark.
contact::ReconstructionOptions ReconstructionOptionsOf(const BridgeConfig& config);

class ContactFeStep final : public FeStep {
 public:
  /// @param model_name  leader fingertip model (linear, bone fixed: the compliance method)
  /// @param profile     three-axis sensor profile with a forward_model
  /// @param registration  sensor pad -> leader pad frame
  /// @param fallback    pressure-map step for scans the reconstruction cannot explain
  /// @param leader      the leader press's options: contact::LeaderComplianceOptions(cache dir, face
  ///                    contact); contact.full_field keeps what frame_positions_m() needs
  ///                    for the whole mesh (VTU frames; 24 MB on B, and the precompute runs
  ///                    instead of the cache)
  /// @param press       the leader press's force and contact tolerances
  ///                    (ReconstructedPressOptions(); fe.contact_tolerance sets its contact one)
  /// @param merkel_filter the Merkel vertices whose SED is computed (empty = the whole
  ///                    layer); the fallback must have been built with the same
  /// @param model       the leader model already loaded with merkel_filter (a hand's fingers
  ///                    share it: bridge/leader_model_cache.h), used read-only; null: loaded here
  ContactFeStep(const std::string& model_name, const sensors::SensorProfile& profile,
                const PadRegistration& registration, std::unique_ptr<FeStep> fallback,
                scene::FingertipComplianceOptions leader, contact::ReconstructionOptions options = {},
                scene::PressToForceOptions press = contact::ReconstructedPressOptions(),
                const model::MerkelVertexFilter& merkel_filter = {},
                std::shared_ptr<const model::FingertipModel> model = nullptr);
  ~ContactFeStep() override;

  /// Needs values.scan (set by ScanConditioner); without it the fallback answers.
  const MerkelSedResult& Step(const TaxelValues& values) override;
  const Eigen::Matrix3Xd& merkel_rest_pad_mm() const override;
  const std::string& model_id() const override { return fallback_->model_id(); }
  std::string Describe() const override;
  std::string CountersLine() const override;
  const contact::ContactReport* contact_report() const override { return &stage_->report(); }
  /// The leader press's options (fe.contact_tolerance is their contact tolerance).
  const scene::PressToForceOptions& press_options() const { return stage_->press_options(); }
  /// With leader.contact.full_field: the leader's mesh under the pressed object and the step's Merkel SED
  /// (a fallback scan shows the fallback's own frame, or rest). False without full_field.
  bool Frame(FeFrame* frame) const override;

  /// Scans no primitive explains (the fit's fallbacks, presses that cannot reach their force,
  /// and with `flagged_too` fits flagged model_inadequate) answered by the surface pressure
  /// (sensors/surface_pressure_inversion.h) pressed on the leader as a traction field
  /// (contact/surface_pressure_on_leader.h) instead of the pressure map (bridge fe.fallback).
  void UseSurfacePressure(const sensors::SensorProfile& profile, const PadRegistration& registration,
                          const sensors::SurfacePressureOptions& options, bool flagged_too);
  /// Scans the surface pressure answered.
  int64_t surface_answers() const { return surface_answers_; }

  /// See contact::ContactStage::set_reuse_press (on by default).
  void set_reuse_press(bool reuse) { stage_->set_reuse_press(reuse); }
  /// See contact::ContactStage::set_skip_known_unreachable (on by default).
  void set_skip_known_unreachable(bool skip) { stage_->set_skip_known_unreachable(skip); }

  /// The last scan's estimate in the leader's pad frame.
  const contact::ContactEstimate& last_estimate() const { return stage_->report().estimate; }
  const contact::ContactStepCounters& counters() const { return stage_->counters(); }
  const contact::ContactReconstructor& reconstructor() const { return stage_->reconstructor(); }
  /// The leader model and its compliance precompute, for another finger to share.
  const std::shared_ptr<const model::FingertipModel>& leader_model() const { return model_; }
  std::shared_ptr<const fem::ComplianceOperator> leader_operator() const;
  /// Wall time per step of the two stages (also in each result's report.stage_ms as
  /// kReconstruction and kPress): reconstruction, and the press on the leader (contact
  /// solves + Merkel SED), over the scans that reached them.
  LatencySummary reconstruction_time() const { return recon_time_.Run(); }
  LatencySummary press_time() const { return press_time_.Run(); }
  /// Thread CPU time per step over the scans that reached the reconstruction (reconstruction
  /// + press + SED, or the fallback's step): the cost without preemption.
  LatencySummary cpu_time() const { return cpu_time_.Run(); }

 private:
  /// The step's result from the stage's answer: zero SED, the leader's, or the fallback's.
  const MerkelSedResult& Answer(const contact::ContactStepOutcome& outcome, const TaxelValues& values,
                                const StageTimes& times);
  /// The fallback's result with this step's stage times added.
  const MerkelSedResult& Fallback(const TaxelValues& values, const StageTimes& times);
  /// The surface pressure's answer (UseSurfacePressure); the map's when it cannot answer.
  const MerkelSedResult& SurfacePressure(const TaxelValues& values, const StageTimes& times);
  /// The stage times of a scan into their run statistics.
  void RecordStageTimes(const contact::ContactStepOutcome& outcome, const StageTimes& times);

  std::shared_ptr<const model::FingertipModel> model_;
  std::unique_ptr<contact::ContactStage> stage_;
  std::unique_ptr<FeStep> fallback_;
  std::unique_ptr<sensors::SurfacePressureInversion> surface_;
  std::unique_ptr<contact::SurfacePressureOnLeader> surface_on_leader_;
  Eigen::Matrix2d surface_rotation_ = Eigen::Matrix2d::Identity();  // sensor pad -> leader pad (shear)
  bool surface_for_flagged_ = false;
  int64_t surface_answers_ = 0;
  enum class LastStep { kNone, kPressed, kFallback } last_ = LastStep::kNone;
  Eigen::VectorXd zero_sed_;
  MerkelSedResult result_;
  // Samples kept for the run's percentiles of each stage time [-]: 100k (400 kB) are enough
  // for a p99 of a counters line; the bridge's own latency keeps the default 4M.
  static constexpr int64_t kStageTimeSamples = 100000;
  LatencyStats recon_time_{kStageTimeSamples}, press_time_{kStageTimeSamples}, cpu_time_{kStageTimeSamples};
};

}  // namespace sedbridge::bridge
