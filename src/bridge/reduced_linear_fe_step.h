#pragma once
// FeStep as one dense product: for the linear quasi-static bridge scene (preset "fast":
// linear elasticity, bone fixed, surface traction only) the displacement is a fixed linear
// function of the taxel values, u = U v with v = [p; s_x; s_y] (per taxel) and
// U = K^-1 B W. U is computed once: the scene's load vector of each unit taxel load, then
// one back-substitution per column on K at rest (fem/stiffness_inverse.h, the precompute the
// compliance operator uses too); a step is then u = U v plus the Merkel-layer SED of the new
// positions. Same result as SceneFeStep up to round-off, at a fraction of its cost.
// A step moves only the nodes the Merkel SED reads (the rows of U for the nodes of the
// layer's elements: most of the mesh for the whole layer, a tenth for a display's
// footprint); the whole mesh is moved for a VTU frame only (Frame).
//
// Refuses (std::invalid_argument) scenes where the map is not linear: corotational
// elasticity, contact, a moving bone, backward Euler; and a matrix-free solver (no K).

#include <memory>
#include <string>

#include "bridge/fe_step.h"
#include "bridge/scene_fe_step.h"

namespace sedbridge::bridge {

class ReducedLinearFeStep final : public FeStep {
 public:
  /// merkel_filter: as SceneFeStep's.
  ReducedLinearFeStep(const scene::SceneDescription& description, const sensors::SensorProfile& profile,
                      const PadRegistration& registration, const TractionFieldOptions& options = {},
                      const model::MerkelVertexFilter& merkel_filter = {});

  const MerkelSedResult& Step(const TaxelValues& values) override;
  const Eigen::Matrix3Xd& merkel_rest_pad_mm() const override { return scene_step_->merkel_rest_pad_mm(); }
  const std::string& model_id() const override { return scene_step_->model_id(); }
  std::string Describe() const override;
  /// The positions U v and the Merkel SED (no traction field: this step never builds one).
  bool Frame(FeFrame* frame) const override;

  /// Displacement per unit taxel value [m/Pa], 3 #soft nodes x (#taxels * #axes); columns
  /// ordered normal (all taxels), then shear x, then shear y.
  const Eigen::MatrixXd& displacement_map() const { return U_; }
  /// Soft-node positions of the last Step() [m], 3 * #soft nodes (rest before the first),
  /// of every node (U v over the whole mesh, computed here).
  Eigen::VectorXd positions_m() const;
  /// The scene step it was built from: its mesh and Merkel layer (its own state is unused).
  SceneFeStep& scene_step() { return *scene_step_; }

 private:
  std::unique_ptr<SceneFeStep> scene_step_;
  int num_taxels_ = 0;
  bool shear_ = false;
  Eigen::MatrixXd U_;
  // The rows of U for the nodes the Merkel SED reads (3 per node, in sed_nodes_ order).
  std::vector<int> sed_nodes_;
  Eigen::MatrixXd U_sed_;
  Eigen::VectorXd rest_m_, x_m_, v_, u_sed_;
  Eigen::VectorXd force_per_Pa_N_;  // applied pressing force per unit pressure of each taxel
  MerkelSedResult result_;
};

}  // namespace sedbridge::bridge
