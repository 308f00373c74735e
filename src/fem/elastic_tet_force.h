#pragma once
// Elastic force of linear tetrahedra: corotational (per-element rotation, paper III-B) or
// plain linear FEM. Optional stiffness-proportional (Rayleigh beta) damping.

#include <Eigen/Geometry>
#include <vector>

#include "fem/force_term.h"
#include "fem/system_matrix.h"
#include "fem/tet_element.h"

namespace sedbridge::fem {

enum class ElasticFormulation { kCorotational, kLinear };

class ElasticTetForce final : public ForceTerm {
 public:
  /// @param mesh            rest mesh (kept by reference; must outlive the term)
  /// @param formulation     corotational or linear
  /// @param rayleigh_beta_s stiffness-proportional damping D = beta K [s]; 0 = none
  ElasticTetForce(const TetMesh& mesh, ElasticFormulation formulation, double rayleigh_beta_s = 0.0);

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
  void ComputeNodeRotations(std::vector<Eigen::Matrix3d>& node_rotations) const;
  /// Elements with det F <= 0 at the last AddForce.
  int inverted_elements() const { return inverted_elements_; }

  const TetMesh& mesh() const { return mesh_; }
  const std::vector<TetElement>& elements() const { return elements_; }
  ElasticFormulation formulation() const { return formulation_; }
  /// Element batches with no shared node (parallel assembly without atomics).
  const std::vector<std::vector<int>>& colors() const { return colors_; }

 private:
  const TetMesh& mesh_;
  ElasticFormulation formulation_;
  double beta_s_;
  std::vector<TetElement> elements_;
  std::vector<std::vector<int>> colors_;
  std::vector<std::array<int, 16>> slots_;
  std::vector<Eigen::Quaterniond> quaternions_;  // warm starts
  std::vector<Eigen::Matrix3d> rotations_;
  std::vector<std::vector<int>> node_elements_;
  int inverted_elements_ = 0;
  // Linear FEM: K0 assembled once; the force is then one sparse product a step.
  SystemMatrix rest_stiffness_;
  Eigen::VectorXd rest_positions_, work_;
};

/// Greedy colouring of tets so that no two tets of one colour share a node.
std::vector<std::vector<int>> ColorElements(const std::vector<Tet>& tets, int num_nodes);

}  // namespace sedbridge::fem
