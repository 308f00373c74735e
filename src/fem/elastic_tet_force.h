#pragma once
// Elastic force of linear tetrahedra: corotational (per-element rotation, paper III-B) or
// plain linear FEM. Optional stiffness-proportional (Rayleigh beta) damping.

#include <Eigen/Geometry>
#include <vector>

#include "common/no_copy_no_move.h"
#include "fem/force_term.h"
#include "fem/node_rotation_source.h"
#include "fem/system_matrix.h"
#include "fem/tet_element.h"

namespace sedbridge::fem {

enum class ElasticFormulation { kCorotational, kLinear };

class ElasticTetForce final : public ForceTerm, public NodeRotationSource {
 public:
  // Holds its own rest-stiffness SystemMatrix and slots bound to the system matrix.
  SEDBRIDGE_NO_COPY_NO_MOVE(ElasticTetForce)

  /// @param mesh            rest mesh (kept by reference; must outlive the term)
  /// @param formulation     corotational or linear
  /// @param rayleigh_beta_s stiffness-proportional damping D = beta K [s]; 0 = none
  /// @param deviatoric_only true: only the deviatoric part 2 mu dev(eps) (lambda replaced
  ///        by -2 mu / 3); the volumetric part is then another term's (NodalPressureTetForce)
  ElasticTetForce(const TetMesh& mesh, ElasticFormulation formulation, double rayleigh_beta_s = 0.0,
                  bool deviatoric_only = false);

  std::string name() const override;
  void AppendCoupledNodes(std::vector<std::pair<int, int>>& pairs) const override;
  void BindMatrix(const SystemMatrix& matrix) override;
  void AddForce(const SystemState& state, Eigen::VectorXd& force_N, JacobianSink* sink) override;
  bool JacobianIsConstant() const override { return formulation_ == ElasticFormulation::kLinear; }
  double PotentialEnergy(const SystemState& state) const override;

  /// Rotation of each element at the last AddForce (identity for linear FEM).
  const std::vector<Eigen::Matrix3d>& rotations() const { return rotations_; }
  /// Per-node rotation (closest rotation to the sum of the adjacent element rotations),
  /// for the warped preconditioner. Computed on demand from rotations().
  void ComputeNodeRotations(std::vector<Eigen::Matrix3d>& node_rotations) const override;
  /// Elements with det F <= 0 at the last AddForce.
  int inverted_elements() const { return inverted_elements_; }

  const TetMesh& mesh() const { return mesh_; }
  const std::vector<TetElement>& elements() const { return elements_; }
  ElasticFormulation formulation() const { return formulation_; }
  bool deviatoric_only() const { return deviatoric_only_; }

 private:
  const TetMesh& mesh_;
  ElasticFormulation formulation_;
  double beta_s_;
  bool deviatoric_only_;
  std::vector<TetElement> elements_;
  std::vector<std::array<int, 16>> slots_;
  std::vector<Eigen::Quaterniond> quaternions_;  // warm starts
  std::vector<Eigen::Matrix3d> rotations_;
  std::vector<std::vector<int>> node_elements_;
  int inverted_elements_ = 0;
  /// Element kernel: force into `force`, Jacobian blocks into `values`/`k_times_v` (laid
  /// out like sink's matrix). Returns 1 if the element is inverted.
  int AccumulateElement(int t, const SystemState& state, bool force, Eigen::VectorXd& force_N, JacobianSink* sink,
                        double* values, Eigen::VectorXd* k_times_v);
  // Threads > 1: per-thread partial sums (thread 0 writes the real buffers), reduced once.
  std::vector<std::vector<double>> thread_values_;
  std::vector<Eigen::VectorXd> thread_force_, thread_k_times_v_;
  // Linear FEM: K0 assembled once; the force is then one sparse product a step.
  SystemMatrix rest_stiffness_;
  Eigen::VectorXd rest_positions_, work_, k_times_work_;
};

}  // namespace sedbridge::fem
