#pragma once
// A fingertip model plus exactly the effects a scene lists, ready to step.

#include <memory>
#include <string>
#include <vector>

#include "fem/penalty_contact_force.h"
#include "scene/fingertip_compliance.h"
#include "fem/simulation.h"
#include "fem/surface_traction_force.h"
#include "model/fingertip_model.h"
#include "scene/merkel_layer.h"
#include "scene/scene_description.h"

namespace sedbridge::scene {

class FingertipScene {
 public:
  /// Loads the scene's model and builds its effects.
  explicit FingertipScene(const SceneDescription& description);
  /// Uses an already loaded model (e.g. to run one model under several scenes).
  FingertipScene(const SceneDescription& description, model::FingertipModel model);

  /// One scene step of dt (quasi-static: one load increment). Also evaluates the
  /// Merkel SED when the scene outputs it. The report's stage_ms has the assembly, solve
  /// and SED times.
  fem::StepReport Step();

  const SceneDescription& description() const { return description_; }
  const model::FingertipModel& model() const { return *model_; }
  fem::Simulation& simulation() { return *simulation_; }
  const fem::Simulation& simulation() const { return *simulation_; }

  /// Built effects, or null when the scene does not use them.
  fem::PenaltyContactForce* contact() const { return contact_; }
  /// The compliance contact solver, built only for `solver.type: compliance`. Step() then
  /// solves contact with it (the simulation's positions are set from it: the pad's and
  /// the Merkel layer's nodes move, the others stay at rest).
  FingertipCompliance* compliance() const { return compliance_.get(); }
  /// Time (quasi-static: load parameter) after the last step [s].
  double time_s() const;
  /// Sum of contact spring forces k depth n on the skin after the last step [N, model frame].
  Eigen::Vector3d ContactSpringForce_N() const;
  fem::SurfaceTractionForce* traction() const { return traction_; }
  MerkelLayer* merkel() const { return merkel_.get(); }
  const fem::ElasticTetForce& elastic() const { return *simulation_->elastic(); }
  /// The nodal pressure term when the scene's elasticity is `nodal_pressure`, else null.
  const fem::NodalPressureTetForce* nodal_pressure() const { return nodal_pressure_; }

  /// Names of the force terms that were built, in evaluation order.
  std::vector<std::string> BuiltEffects() const;
  /// Skin area owned by each soft node [m^2] (one third of adjacent skin triangles).
  const Eigen::VectorXd& skin_node_area_m2() const { return skin_area_m2_; }
  /// Skin area of nodes currently in contact [m^2].
  double ContactArea_m2() const;

 private:
  void Build();
  /// The Merkel SED at the current positions, when the scene outputs it (timed as kSed).
  void EvaluateMerkelSed(StageTimes& times);

  SceneDescription description_;
  std::unique_ptr<model::FingertipModel> model_;
  std::unique_ptr<fem::Simulation> simulation_;
  fem::PenaltyContactForce* contact_ = nullptr;
  fem::SurfaceTractionForce* traction_ = nullptr;
  std::unique_ptr<MerkelLayer> merkel_;
  const fem::NodalPressureTetForce* nodal_pressure_ = nullptr;
  std::unique_ptr<FingertipCompliance> compliance_;
  double compliance_t_s_ = 0;
  Eigen::VectorXd skin_area_m2_;
};

}  // namespace sedbridge::scene
