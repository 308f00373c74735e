#pragma once
// A low-rank (Woodbury) update of a rest-matrix factor by the stiffness a few nodes carry
// beyond the rest matrix: penalty contact springs are ~100x the elastic diagonal at a 1 ms
// step, so a warped rest factor without them needs ~20 PCG iterations where it needs ~3 on
// the same step without contact (docs/performance.md, "Contact in the warped preconditioner").
//
// For the nodes given, C_i = R_i^T A_ii R_i - A0_ii (the step's diagonal block turned into
// the rest frame, minus the rest matrix's) is split into eigenpairs; those above a fraction
// of A0_ii make U (columns e_i (x) v) and Lambda, and the preconditioner becomes the exact
// inverse of A0 + U Lambda U^T:
//   (A0 + U L U^T)^-1 r = y - Z S^-1 (U^T y),  y = A0^-1 r,  Z = A0^-1 U,  S = L^-1 + U^T Z.
// Z comes from the columns A0^-1 (e_i (x) I3), solved once per node and cached (bounded by a
// memory budget; a node that does not fit is left out, which only weakens the update).

#include <Eigen/Core>
#include <Eigen/Cholesky>
#include <functional>
#include <unordered_map>
#include <vector>

#include "fem/system_matrix.h"

namespace sedbridge::fem {

class StiffNodeUpdate {
 public:
  /// x = A0^-1 b with the rest factor.
  using RestSolve = std::function<void(const Eigen::VectorXd& b, Eigen::VectorXd& x)>;

  /// @param column_budget_bytes memory for cached columns of A0^-1 (3 per node)
  /// @param relative_threshold  eigenvalues of C_i below this times A0_ii's mean diagonal are dropped
  explicit StiffNodeUpdate(double column_budget_bytes = 64e6, double relative_threshold = 0.1);

  /// Keeps A0's diagonal blocks and forgets cached columns (a new rest factor).
  void SetRestMatrix(const SystemMatrix& A0);
  /// Builds U, Lambda, Z and S for this step's matrix A.
  /// @param nodes     the stiff nodes (duplicates allowed)
  /// @param rotations per-node rotations of the warped factor (empty = none)
  void Prepare(const SystemMatrix& A, const std::vector<int>& nodes, const std::vector<Eigen::Matrix3d>& rotations,
               const RestSolve& rest_solve);
  /// Block (i, i) of this step's matrix.
  using DiagonalBlockOf = std::function<Eigen::Matrix3d(int node)>;
  /// Same with A given by its diagonal blocks (a matrix-free step, fem/step_operator.h).
  void Prepare(int num_nodes, const DiagonalBlockOf& diagonal_block, const std::vector<int>& nodes,
               const std::vector<Eigen::Matrix3d>& rotations, const RestSolve& rest_solve);
  /// y = A0^-1 r (rest frame) in, (A0 + U L U^T)^-1 r out.
  void Apply(Eigen::VectorXd& y) const;

  int rank() const { return int(pairs_.size()); }
  /// Back-substitutions spent on cached columns so far (3 per node that entered the cache).
  long column_solves() const { return column_solves_; }
  int nodes_left_out() const { return left_out_; }

 private:
  struct Pair {
    int node;
    Eigen::Vector3d direction;  // rest frame, unit
    double stiffness;           // eigenvalue of C_i
  };
  int CachedColumns(int node, const RestSolve& rest_solve);

  double budget_bytes_;
  double threshold_;
  std::vector<Eigen::Matrix3d> rest_diagonal_;
  // Cache of A0^-1 (e_i (x) I3): slot -> n x 3 columns; node -> slot; slot -> node, last use.
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, 3>> columns_;
  std::unordered_map<int, int> slot_of_node_;
  std::vector<int> node_of_slot_;
  std::vector<long> last_used_;
  long stamp_ = 0;
  long column_solves_ = 0;
  int left_out_ = 0;

  std::vector<Pair> pairs_;
  Eigen::MatrixXd z_;  // A0^-1 U
  Eigen::LLT<Eigen::MatrixXd> s_factor_;
  mutable Eigen::VectorXd t_, s_;  // Apply's workspace (once per PCG iteration)
};

}  // namespace sedbridge::fem
