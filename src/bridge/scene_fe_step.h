#pragma once
// FeStep on a scene::FingertipScene with a surface-traction term: the reference
// implementation (quasi-static, bone fixed; with the "fast" preset the system matrix is
// factorized once and a step is one back-substitution).

#include <memory>
#include <string>

#include "bridge/fe_step.h"
#include "bridge/pressure_boundary_condition.h"
#include "scene/fingertip_scene.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::bridge {

/// The scene a bridge runs: `model`, `preset`, bone fixed, surface traction on, quasi-static,
/// one step per scan, Merkel SED output. Throws std::invalid_argument for an unknown preset.
scene::SceneDescription BridgeSceneDescription(const std::string& model, const std::string& preset);

/// Loads the model named `name` (model::LoadFingertipModel) with only the Merkel vertices
/// `merkel_filter` accepts (all when it is empty).
model::FingertipModel LoadBridgeModel(const std::string& name, const model::MerkelVertexFilter& merkel_filter);

/// OpenMP threads of the FE kernels (omp_set_num_threads). The bridge defaults to 1: its
/// per-step work is small, and on a shared 2-core machine spinning OpenMP workers cost
/// more than they gain (the measurement: docs/bridge.md, "Timing").
void SetFeThreads(int threads);

class SceneFeStep final : public FeStep {
 public:
  /// A step whose relative linear residual exceeds this is not used [-].
  static constexpr double kMaxLinearResidual = 1e-2;

  /// Builds the scene (loads the model: may take a second) and the boundary condition, and
  /// runs one unloaded step so the factorization happens here, not on the first scan.
  /// merkel_filter: the Merkel vertices whose SED is computed (model::KeepMerkelVertices;
  /// empty = the whole layer).
  SceneFeStep(const scene::SceneDescription& description, const sensors::SensorProfile& profile,
              const PadRegistration& registration, const TractionFieldOptions& options = {},
              const model::MerkelVertexFilter& merkel_filter = {});

  const MerkelSedResult& Step(const TaxelValues& values) override;
  const Eigen::Matrix3Xd& merkel_rest_pad_mm() const override;
  const std::string& model_id() const override { return model_id_; }
  std::string Describe() const override;
  /// The scene's positions, the traction field and the Merkel SED.
  bool Frame(FeFrame* frame) const override;

  scene::FingertipScene& scene() { return *scene_; }
  /// The load vector [N] (3 #soft nodes, model frame) of `values` on the scene at rest,
  /// without a step; its force along -z_pad in *applied_force_N. The scene's traction is
  /// left at these values.
  Eigen::VectorXd LoadVector(const TaxelValues& values, double* applied_force_N);
  const PressureBoundaryCondition& boundary_condition() const { return *bc_; }

 private:
  std::unique_ptr<scene::FingertipScene> scene_;
  std::unique_ptr<PressureBoundaryCondition> bc_;
  std::string model_id_;
  MerkelSedResult result_;
};

}  // namespace sedbridge::bridge
