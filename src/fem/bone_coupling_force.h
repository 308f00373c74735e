#pragma once
// Penalty attachment of soft tissue to the rigid bone/nail (paper Fig. 2a): a spring-damper
// from each attached node to its anchor on the rigid body. Anisotropic: stiffness k along
// the bone-surface normal and a*k tangentially (a = 1: isotropic, the paper's setting).
// The bone pose is fixed or follows a trajectory (a tracked finger).

#include <memory>
#include <vector>

#include "fem/force_term.h"
#include "common/geometry/trajectory.h"

namespace sedbridge::fem {

struct SpringDamperParams {
  double stiffness_N_m = 200.0;  ///< k, per node
  double damping_N_s_m = 0.1;    ///< b, per node
  double anisotropy = 1.0;       ///< a: tangential / normal ratio
};

class BoneCouplingForce final : public ForceTerm {
 public:
  /// @param rest_positions_m  rest positions of all nodes (3 x n)
  /// @param attached_nodes    nodes tied to the bone
  /// @param normals           unit bone-surface normal per attached node (ignored if a = 1)
  /// @param bone_motion       bone pose over time (model frame), relative to its rest pose;
  ///                          null = fixed
  BoneCouplingForce(const Eigen::Matrix3Xd& rest_positions_m, std::vector<int> attached_nodes,
                    std::vector<Eigen::Vector3d> normals, SpringDamperParams params,
                    std::shared_ptr<const geometry::Trajectory> bone_motion = nullptr);

  std::string name() const override { return "bone_coupling"; }
  void BindMatrix(const SystemMatrix& matrix) override;
  void AddForce(const SystemState& state, Eigen::VectorXd& force_N, JacobianSink* sink) override;
  bool JacobianIsConstant() const override { return motion_ == nullptr; }
  double PotentialEnergy(const SystemState& state) const override;

  const std::vector<int>& attached_nodes() const { return nodes_; }
  /// Anchor of attached node k at time t.
  Eigen::Vector3d Anchor(size_t k, double t_s) const;

 private:
  std::vector<int> nodes_;
  std::vector<Eigen::Vector3d> rest_;
  std::vector<Eigen::Matrix3d> stiffness_;  // per node, rest frame
  std::vector<int> slots_;
  SpringDamperParams params_;
  std::shared_ptr<const geometry::Trajectory> motion_;
};

}  // namespace sedbridge::fem
