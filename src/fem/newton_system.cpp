#include "fem/newton_system.h"

#include <algorithm>

namespace sedbridge::fem {

NewtonSystem::NewtonSystem(int num_nodes, const std::vector<std::unique_ptr<ForceTerm>>& terms,
                           std::unique_ptr<LinearSolver> solver)
    : terms_(terms), solver_(std::move(solver)) {
  std::vector<std::pair<int, int>> pairs;
  for (const auto& term : terms_) {
    const size_t before = pairs.size();
    term->AppendCoupledNodes(pairs);
    if (pairs.size() > before) coupling_terms_.push_back(term.get());
    constant_matrix_ = constant_matrix_ && term->JacobianIsConstant();
  }
  matrix_.Build(num_nodes, pairs);
  for (const auto& term : terms_) term->BindMatrix(matrix_);
  force_ = Eigen::VectorXd::Zero(3 * num_nodes);
  if (solver_->accepts_operator()) solver_->SetOperator(&operator_);
}

void NewtonSystem::Operator::Multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  const NewtonSystem& s = system_;
  if (!s.matrix_free_) {
    s.matrix_.Multiply(x, y);
    return;
  }
  if (s.diagonal_packed_) SystemMatrix::MultiplyPackedBlocks(s.diagonal_blocks_, x, y);
  else s.matrix_.MultiplyDiagonalBlocks(x, y);
  for (ForceTerm* term : s.coupling_terms_) term->AddJacobianTimes(s.stiffness_scale_, s.damping_scale_, x, y);
}

const SystemMatrix& NewtonSystem::Operator::AssembledMatrix() {
  NewtonSystem& s = system_;
  if (s.matrix_free_ && s.matrix_state_) {
    JacobianSink sink{&s.matrix_, s.stiffness_scale_, s.damping_scale_};
    s.scratch_force_.setZero(s.force_.size());
    for (ForceTerm* term : s.coupling_terms_) term->AddForce(*s.matrix_state_, s.scratch_force_, &sink);
    s.matrix_free_ = false;
    s.diagonal_packed_ = false;
  }
  return s.matrix_;
}

Eigen::Matrix3d NewtonSystem::Operator::DiagonalBlock(int node) const {
  const NewtonSystem& s = system_;
  Eigen::Matrix3d block = s.diagonal_packed_
                              ? Eigen::Matrix3d(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
                                    s.diagonal_blocks_.data() + 9 * size_t(node)))
                              : s.matrix_.Block(s.matrix_.DiagonalSlot(node));
  if (s.matrix_free_)
    for (const ForceTerm* term : s.coupling_terms_)
      block += term->JacobianDiagonalBlock(node, s.stiffness_scale_, s.damping_scale_);
  return block;
}

void NewtonSystem::Assemble(const SystemState& s, double ks, double kd, bool with_matrix, bool k_times_v,
                            StageTimes* times) {
  StageTimes unused;
  const StageTimer timer(times ? *times : unused, Stage::kAssembly);
  force_.setZero(s.x_m.size());
  JacobianSink sink{&matrix_, ks, kd};
  if (k_times_v) {
    k_times_v_.setZero(s.x_m.size());
    sink.velocity = &s.v_m_s;
    sink.stiffness_times_velocity = &k_times_v_;
  }
  bool matrix_free = false;
  if (with_matrix) {
    // The first matrix is assembled whole: it is the reference a warped solver factorizes.
    matrix_free = matrix_ready_ && !constant_matrix_ && solver_->accepts_operator() &&
                  std::all_of(coupling_terms_.begin(), coupling_terms_.end(),
                              [](const ForceTerm* t) { return t->AppliesJacobian(); });
    // After a matrix-free assembly the off-diagonal blocks are still zero.
    if (matrix_free && matrix_free_) matrix_.SetDiagonalZero();
    else matrix_.SetZero();
    matrix_free_ = matrix_free;
    diagonal_packed_ = false;
    stiffness_scale_ = ks;
    damping_scale_ = kd;
    matrix_state_.emplace(s);
  }
  auto sink_for = [&](const ForceTerm* term) -> JacobianSink* {
    if (!with_matrix) return nullptr;
    if (matrix_free && std::find(coupling_terms_.begin(), coupling_terms_.end(), term) != coupling_terms_.end())
      return nullptr;
    return &sink;
  };
  const bool split = with_matrix && !matrix_ready_ && solver_->wants_reference_matrix();
  // Terms in order, except that for the reference matrix those not in it come last (in
  // their own order) so that their values can be told apart.
  for (const auto& term : terms_)
    if (!split || term->InRestMatrix()) term->AddForce(s, force_, sink_for(term.get()));
  if (matrix_free && k_times_v)
    for (ForceTerm* term : coupling_terms_) term->AddJacobianTimes(1.0, 0.0, s.v_m_s, k_times_v_);
  if (!split) return;
  const double* values = matrix_.values();
  not_in_rest_values_.assign(values, values + matrix_.num_values());
  for (const auto& term : terms_)
    if (!term->InRestMatrix()) term->AddForce(s, force_, &sink);
  for (size_t k = 0; k < not_in_rest_values_.size(); ++k) not_in_rest_values_[k] = values[k] - not_in_rest_values_[k];
}

void NewtonSystem::PrepareSolver(StageTimes& times) {
  const StageTimer timer(times, Stage::kSolve);
  if (!matrix_ready_ && solver_->wants_reference_matrix()) {
    double* values = matrix_.values();
    const bool split = not_in_rest_values_.size() == size_t(matrix_.num_values());
    if (split)
      for (size_t k = 0; k < not_in_rest_values_.size(); ++k) values[k] -= not_in_rest_values_[k];
    solver_->SetReferenceMatrix(matrix_);
    if (split)
      for (size_t k = 0; k < not_in_rest_values_.size(); ++k) values[k] += not_in_rest_values_[k];
    not_in_rest_values_.clear();
  }
  if (matrix_free_) {
    matrix_.GatherDiagonalBlocks(diagonal_blocks_);
    diagonal_packed_ = true;
  }
  solver_->Prepare(matrix_);
  matrix_ready_ = true;
}

LinearSolveReport NewtonSystem::Solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& delta, StepReport& report) {
  const LinearSolveReport lr = TrySolve(rhs, delta, report.stage_ms);
  Record(lr, report);
  return lr;
}

LinearSolveReport NewtonSystem::TrySolve(const Eigen::VectorXd& rhs, Eigen::VectorXd& delta, StageTimes& times) {
  const StageTimer timer(times, Stage::kSolve);
  return solver_->Solve(matrix_, rhs, delta);
}

bool NewtonSystem::UseDefiniteJacobians(bool definite) {
  bool any = false;
  for (const auto& term : terms_) any = term->UseDefiniteJacobian(definite) || any;
  return any;
}

void NewtonSystem::Record(const LinearSolveReport& lr, StepReport& report) {
  report.newton_iterations++;
  report.linear_iterations += lr.iterations;
  report.linear_residual = std::max(report.linear_residual, lr.relative_residual);
  report.solver_fallbacks += lr.used_fallback ? 1 : 0;
  report.converged = report.converged && lr.converged;
}

}  // namespace sedbridge::fem
