#include "fem/linear_solver.h"

#include "fem/cholmod_solver.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

namespace sedbridge::fem {
namespace {

// The preconditioner's per-node rotations: a parallel region costs a few microseconds,
// one thread's pass over B's 1793 nodes about ten.
constexpr int kParallelMinNodes = 1000;

// The CSR arrays of a symmetric matrix read as CSC describe the same matrix.
Eigen::Map<const Eigen::SparseMatrix<double>> AsColumnMajor(const SystemMatrix& A) {
  const auto& m = A.csr();
  return Eigen::Map<const Eigen::SparseMatrix<double>>(m.rows(), m.cols(), m.nonZeros(), m.outerIndexPtr(),
                                                       m.innerIndexPtr(), m.valuePtr());
}

}  // namespace

void DirectLdltSolver::Prepare(const SystemMatrix& A) {
  const Eigen::SparseMatrix<double> a = AsColumnMajor(A);
  if (!analyzed_) {
    ldlt_.analyzePattern(a);
    analyzed_ = true;
  }
  ldlt_.factorize(a);
  ok_ = ldlt_.info() == Eigen::Success;
}

LinearSolveReport DirectLdltSolver::Solve(const SystemMatrix&, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  LinearSolveReport report;
  if (!ok_) {
    report.converged = false;
    return report;
  }
  if (b.isZero(0.0)) {  // at rest: nothing to solve (keeps long idle runs cheap)
    x.setZero(b.size());
    return report;
  }
  x = ldlt_.solve(b);
  report.converged = x.allFinite();
  return report;
}

std::unique_ptr<LinearSolver> MakeDirectSolver(DirectSolverKind kind) {
  if (kind == DirectSolverKind::kCholmod) return std::make_unique<CholmodSolver>();
  return std::make_unique<DirectLdltSolver>();
}

PcgSolver::PcgSolver(PcgSettings settings, const NodeRotationSource* rotations, const StiffNodeSource* stiff_nodes)
    : settings_(settings),
      rotation_source_(rotations),
      stiff_source_(stiff_nodes),
      stiff_update_(settings.stiff_node_budget_MB * 1e6),
      rest_factor_(MakeDirectSolver(settings.direct)), fallback_(MakeDirectSolver(settings.direct)) {
  if (auto* cholmod = dynamic_cast<CholmodSolver*>(rest_factor_.get()))
    cholmod->set_single_precision(settings_.single_precision_factor);
}

std::string PcgSolver::name() const {
  switch (settings_.preconditioner) {
    case PreconditionerKind::kBlockJacobi: return "pcg_jacobi";
    case PreconditionerKind::kWarpedRestFactor:
      return settings_.direct == DirectSolverKind::kCholmod ? "pcg_warp" : "pcg_warp_ldlt";
    case PreconditionerKind::kWarpedRestIncompleteCholesky: return "pcg_warp_ichol";
  }
  return "pcg";
}

void PcgSolver::SetReferenceMatrix(const SystemMatrix& A0) {
  const Eigen::SparseMatrix<double> a = AsColumnMajor(A0);
  if (settings_.preconditioner == PreconditionerKind::kWarpedRestIncompleteCholesky) {
    rest_incomplete_.compute(a);
    has_rest_factor_ = rest_incomplete_.info() == Eigen::Success;
  } else {
    rest_factor_->Prepare(A0);
    // A zero right-hand side probes the factor's state without solving anything.
    Eigen::VectorXd probe;
    has_rest_factor_ = rest_factor_->Solve(A0, Eigen::VectorXd::Zero(a.rows()), probe).converged;
    if (has_rest_factor_) stiff_update_.SetRestMatrix(A0);
  }
}

void PcgSolver::Prepare(const SystemMatrix& A) {
  if (warped() && rotation_source_) rotation_source_->ComputeNodeRotations(rotations_);
  if (settings_.preconditioner == PreconditionerKind::kWarpedRestFactor && has_rest_factor_ && stiff_source_ &&
      settings_.stiff_node_update) {
    stiff_nodes_.clear();
    stiff_source_->AppendStiffNodes(stiff_nodes_);
    stiff_update_.Prepare(A.num_nodes(), [&](int i) { return DiagonalBlock(A, i); }, stiff_nodes_, rotations_,
                          [&](const Eigen::VectorXd& b, Eigen::VectorXd& x) { rest_factor_->Solve(A, b, x); });
  }
  if (settings_.preconditioner == PreconditionerKind::kBlockJacobi || !has_rest_factor_) {  // also the fallback
    block_inverse_.resize(size_t(A.num_nodes()));
    for (int i = 0; i < A.num_nodes(); ++i) {
      const Eigen::Matrix3d d = DiagonalBlock(A, i);
      const Eigen::Matrix3d inv = d.inverse();
      block_inverse_[size_t(i)] = inv.allFinite() ? inv : Eigen::Matrix3d::Identity();
    }
  }
}

void PcgSolver::ApplyPreconditioner(const SystemMatrix& A, const Eigen::VectorXd& r, Eigen::VectorXd& z) {

  const int n = int(r.size() / 3);
  if (settings_.preconditioner != PreconditionerKind::kBlockJacobi && has_rest_factor_) {
    const bool incomplete = settings_.preconditioner == PreconditionerKind::kWarpedRestIncompleteCholesky;
    auto solve = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
      if (incomplete) out = rest_incomplete_.solve(v);
      else rest_factor_->Solve(A, v, out);  // a direct solver reads its factor, not A
    };
    if (!rotations_.empty()) {
      tmp_.resize(r.size());
#pragma omp parallel for schedule(static) if (n >= kParallelMinNodes)
      for (int i = 0; i < n; ++i) tmp_.segment<3>(3 * i) = rotations_[size_t(i)].transpose() * r.segment<3>(3 * i);
      solve(tmp_, z);
      if (!incomplete) stiff_update_.Apply(z);
#pragma omp parallel for schedule(static) if (n >= kParallelMinNodes)
      for (int i = 0; i < n; ++i) z.segment<3>(3 * i) = rotations_[size_t(i)] * z.segment<3>(3 * i).eval();
    } else {
      solve(r, z);
      if (!incomplete) stiff_update_.Apply(z);
    }
    return;
  }
  z.resize(r.size());
  for (int i = 0; i < n; ++i) z.segment<3>(3 * i) = block_inverse_[size_t(i)] * r.segment<3>(3 * i);
}

LinearSolveReport PcgSolver::Solve(const SystemMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  LinearSolveReport report;
  const double b_norm = b.norm();
  if (x.size() != b.size() || !x.allFinite()) x.setZero(b.size());
  if (b_norm == 0) {
    x.setZero();
    return report;
  }
  Multiply(A, x, q_);
  // CG minimizes phi(x) = x.Ax/2 - b.x from the initial guess. A warm start worse than
  // x = 0 (phi > 0, e.g. last step's dv when the motion reverses) would make a capped,
  // accepted solve worse than no update at all and feed back step after step; starting
  // from zero instead makes every accepted iterate a descent step (phi <= 0).
  if (0.5 * x.dot(q_) - b.dot(x) > 0) {
    x.setZero();
    r_ = b;
  } else {
    r_ = b - q_;
  }
  ApplyPreconditioner(A, r_, z_);
  ++report.preconditioner_applications;
  p_ = z_;
  double rz = r_.dot(z_);
  const double target = settings_.relative_tolerance * b_norm;
  double r_norm = r_.norm();
  int it = 0;
  while (r_norm > target && it < settings_.max_iterations) {
    Multiply(A, p_, q_);
    const double pq = p_.dot(q_);
    if (!(pq > 0)) break;  // not SPD along p (or NaN): let the fallback decide
    const double alpha = rz / pq;
    x += alpha * p_;
    r_ -= alpha * q_;
    r_norm = r_.norm();
    ++it;
    // At the cap too: the next direction would need a preconditioner application that no
    // iteration uses (a capped step paid for two where it used one).
    if (r_norm <= target || it >= settings_.max_iterations) break;
    ApplyPreconditioner(A, r_, z_);
    ++report.preconditioner_applications;
    const double rz_new = r_.dot(z_);
    p_ = z_ + (rz_new / rz) * p_;
    rz = rz_new;
  }
  report.iterations = it;
  report.relative_residual = r_norm / b_norm;
  report.converged = r_norm <= target && x.allFinite();
  if (!report.converged && settings_.fallback_to_direct) {
    ++fallbacks_;
    const SystemMatrix& full = op_ ? op_->AssembledMatrix() : A;
    fallback_->Prepare(full);
    const LinearSolveReport direct = fallback_->Solve(full, b, x);
    report.used_fallback = true;
    report.converged = direct.converged;
    full.Multiply(x, q_);
    report.relative_residual = (b - q_).norm() / b_norm;
  }
  if (!x.allFinite()) {
    // A singular A can drive CG to 0/0 and the direct fallback cannot answer either:
    // hand back "no update" and say so, never NaN.
    x.setZero(b.size());
    report.converged = false;
  }
  return report;
}

const config::EnumNames<LinearSolverKind>& NamesOf(LinearSolverKind) {
  static const config::EnumNames<LinearSolverKind> names{
      {LinearSolverKind::kLdlt, "ldlt"},          {LinearSolverKind::kCholmod, "cholmod"},
      {LinearSolverKind::kPcgJacobi, "pcg_jacobi"}, {LinearSolverKind::kPcgWarp, "pcg_warp"},
      {LinearSolverKind::kPcgWarpLdlt, "pcg_warp_ldlt"}, {LinearSolverKind::kPcgWarpIchol, "pcg_warp_ichol"}};
  return names;
}

std::vector<std::string> LinearSolverNames() { return config::AllNames<LinearSolverKind>(); }

std::unique_ptr<LinearSolver> MakeLinearSolver(const std::string& name, const PcgSettings& pcg,
                                               const NodeRotationSource* rotations,
                                               const StiffNodeSource* stiff_nodes) {
  PcgSettings s = pcg;
  switch (config::ParseEnum<LinearSolverKind>(name, "linear solver")) {
    case LinearSolverKind::kLdlt: return std::make_unique<DirectLdltSolver>();
    case LinearSolverKind::kCholmod: return std::make_unique<CholmodSolver>();
    case LinearSolverKind::kPcgJacobi: s.preconditioner = PreconditionerKind::kBlockJacobi; break;
    case LinearSolverKind::kPcgWarp:
      s.preconditioner = PreconditionerKind::kWarpedRestFactor;
      s.direct = DirectSolverKind::kCholmod;
      break;
    case LinearSolverKind::kPcgWarpLdlt:
      s.preconditioner = PreconditionerKind::kWarpedRestFactor;
      s.direct = DirectSolverKind::kLdlt;
      break;
    case LinearSolverKind::kPcgWarpIchol: s.preconditioner = PreconditionerKind::kWarpedRestIncompleteCholesky; break;
  }
  return std::make_unique<PcgSolver>(s, rotations, stiff_nodes);
}

}  // namespace sedbridge::fem
