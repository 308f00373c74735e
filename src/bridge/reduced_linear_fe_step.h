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
//
// The precompute (scene, U) depends on the model, the preset, the sensor's taxels, the
// registration, the traction options and the Merkel region only: the fingers of a hand with
// the same sensor profile share one (ReducedLinearPrecompute, bridge/leader_model_cache.h),
// read-only; each step keeps its own positions and its own copy of the Merkel layer, whose
// evaluation keeps warm starts (the shared scene's layer is never evaluated).

#include <memory>
#include <string>

#include "bridge/fe_step.h"
#include "bridge/scene_fe_step.h"

namespace sedbridge::bridge {

/// What ReducedLinearFeStep builds once (const after construction).
struct ReducedLinearPrecompute {
  std::unique_ptr<SceneFeStep> scene_step;  ///< the mesh, K and the Merkel layer to copy
  int num_taxels = 0;
  bool shear = false;
  Eigen::MatrixXd U;
  /// The rows of U for the nodes the Merkel SED reads (3 per node, in sed_nodes order).
  std::vector<int> sed_nodes;
  Eigen::MatrixXd U_sed;
  Eigen::VectorXd rest_m;
  Eigen::VectorXd force_per_Pa_N;  ///< applied pressing force per unit pressure of each taxel
};

class ReducedLinearFeStep final : public FeStep {
 public:
  /// merkel_filter: as SceneFeStep's.
  ReducedLinearFeStep(const scene::SceneDescription& description, const sensors::SensorProfile& profile,
                      const PadRegistration& registration, const TractionFieldOptions& options = {},
                      const model::MerkelVertexFilter& merkel_filter = {});
  /// A step on a precompute another step built (shared read-only; null throws).
  explicit ReducedLinearFeStep(std::shared_ptr<const ReducedLinearPrecompute> precompute);
  std::shared_ptr<const ReducedLinearPrecompute> precompute() const { return pre_; }

  const MerkelSedResult& Step(const TaxelValues& values) override;
  const Eigen::Matrix3Xd& merkel_rest_pad_mm() const override { return pre_->scene_step->merkel_rest_pad_mm(); }
  const std::string& model_id() const override { return pre_->scene_step->model_id(); }
  std::string Describe() const override;
  /// The positions U v and the Merkel SED (no traction field: this step never builds one).
  bool Frame(FeFrame* frame) const override;

  /// Displacement per unit taxel value [m/Pa], 3 #soft nodes x (#taxels * #axes); columns
  /// ordered normal (all taxels), then shear x, then shear y.
  const Eigen::MatrixXd& displacement_map() const { return pre_->U; }
  /// Soft-node positions of the last Step() [m], 3 * #soft nodes (rest before the first),
  /// of every node (U v over the whole mesh, computed here).
  Eigen::VectorXd positions_m() const;
  /// The scene step it was built from: its mesh and Merkel layer (its own state is unused;
  /// shared with every step on the same precompute).
  const SceneFeStep& scene_step() const { return *pre_->scene_step; }

 private:
  void StartState();  // positions at rest, own Merkel layer, zero taxel vector

  std::shared_ptr<const ReducedLinearPrecompute> pre_;
  std::unique_ptr<scene::MerkelLayer> merkel_;  // this step's copy (warm starts)
  Eigen::VectorXd x_m_, v_, u_sed_;
  MerkelSedResult result_;
};

}  // namespace sedbridge::bridge
