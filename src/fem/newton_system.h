#pragma once
// The pieces of a Newton iteration every integrator shares, written once: evaluate the
// force terms and (when asked) assemble their Jacobians into the fixed-pattern system
// matrix, prepare the linear solver after the matrix changed, solve and sum the solve
// into the step's report.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "common/no_copy_no_move.h"
#include "fem/force_term.h"
#include "fem/integrator.h"
#include "fem/linear_solver.h"
#include "fem/step_operator.h"
#include "fem/system_matrix.h"

namespace sedbridge::fem {

class NewtonSystem {
 public:
  SEDBRIDGE_NO_COPY_NO_MOVE(NewtonSystem)

  /// @param num_nodes mesh nodes (the system has 3 * num_nodes unknowns)
  /// @param terms     force terms, evaluated in this order (kept by reference)
  /// @param solver    linear solver for the step system
  NewtonSystem(int num_nodes, const std::vector<std::unique_ptr<ForceTerm>>& terms,
               std::unique_ptr<LinearSolver> solver);

  /// Forces at `state` into force_N() and, with_matrix, the system matrix
  /// stiffness_scale K + damping_scale D; with k_times_v, also K v of the state's
  /// velocity into stiffness_times_velocity(). Its wall time goes to times[kAssembly]
  /// when given. Matrix-free (the solver accepts an operator, the matrix is not constant
  /// and was assembled once, and every term that couples nodes applies its own Jacobian):
  /// the matrix then holds only the diagonal blocks of the other terms, and the solver
  /// takes A as the StepOperator (fem/step_operator.h) handed to it at construction.
  /// `state`'s vectors must stay unchanged until the solve is done (a direct fallback
  /// assembles the rest of the matrix at that state).
  void Assemble(const SystemState& state, double stiffness_scale, double damping_scale, bool with_matrix,
                bool k_times_v = false, StageTimes* times = nullptr);
  /// After the matrix was assembled: hands the first one to the solver as its reference
  /// (rest) matrix if it wants one, without the terms that are not InRestMatrix() (contact
  /// springs present at that moment would stay in the rest factor for good), then prepares
  /// (factorizes) the solver. Its wall time goes to times[kSolve].
  void PrepareSolver(StageTimes& times);
  /// Solves matrix() delta = rhs (delta holds the initial guess) and sums the solve into
  /// `report` as one Newton iteration (its wall time into report.stage_ms[kSolve]).
  LinearSolveReport Solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& delta, StepReport& report);
  /// Solve without summing it into a report (its wall time into times[kSolve]): for a
  /// solve that may be retried. Record() sums the one that counts.
  LinearSolveReport TrySolve(const Eigen::VectorXd& rhs, Eigen::VectorXd& delta, StageTimes& times);
  /// Sums a solve into `report` as one Newton iteration.
  static void Record(const LinearSolveReport& lr, StepReport& report);
  /// Asks every term for its positive definite Jacobian (or back to the exact one):
  /// ForceTerm::UseDefiniteJacobian. True if any term has one.
  bool UseDefiniteJacobians(bool definite);

  /// True if every term's Jacobian is constant (the matrix is assembled once).
  bool constant_matrix() const { return constant_matrix_; }
  /// True once the solver was prepared on an assembled matrix.
  bool matrix_ready() const { return matrix_ready_; }
  SystemMatrix& matrix() { return matrix_; }
  const SystemMatrix& matrix() const { return matrix_; }
  const Eigen::VectorXd& force_N() const { return force_; }
  const Eigen::VectorXd& stiffness_times_velocity() const { return k_times_v_; }
  const LinearSolver& solver() const { return *solver_; }
  /// True when the last assembly with a matrix was matrix-free.
  bool matrix_free() const { return matrix_free_; }

 private:
  const std::vector<std::unique_ptr<ForceTerm>>& terms_;
  class Operator final : public StepOperator {
   public:
    explicit Operator(NewtonSystem& system) : system_(system) {}
    void Multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override;
    Eigen::Matrix3d DiagonalBlock(int node) const override;
    const SystemMatrix& AssembledMatrix() override;

   private:
    NewtonSystem& system_;
  };

  std::unique_ptr<LinearSolver> solver_;
  SystemMatrix matrix_;
  Operator operator_{*this};
  std::vector<ForceTerm*> coupling_terms_;  // terms with off-diagonal blocks
  // The last assembly with a matrix left their blocks out (its off-diagonal blocks are then
  // zero), and no fallback has added them since.
  bool matrix_free_ = false;
  double stiffness_scale_ = 1.0, damping_scale_ = 0.0;  // of that assembly
  std::optional<SystemState> matrix_state_;             // ... and its state (AssembledMatrix)
  // Of a matrix-free step's matrix once it is complete (PrepareSolver): its diagonal
  // blocks packed, which the operator's products and diagonal blocks read.
  std::vector<double> diagonal_blocks_;
  bool diagonal_packed_ = false;
  Eigen::VectorXd scratch_force_;
  Eigen::VectorXd force_, k_times_v_;
  bool constant_matrix_ = true;
  bool matrix_ready_ = false;
  // First assembly for a solver that wants a rest matrix: the values the terms that are
  // not InRestMatrix() added, subtracted while the reference is taken.
  std::vector<double> not_in_rest_values_;
};

}  // namespace sedbridge::fem
