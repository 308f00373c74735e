#include "fem/simulation.h"

#include <cmath>
#include <stdexcept>

#include "fem/lumped_mass.h"

namespace sedbridge::fem {
namespace {

// One Newton iteration's linear solve, summed into the step's report.
void AddNewtonIteration(const LinearSolveReport& lr, StepReport& report) {
  report.newton_iterations++;
  report.linear_iterations += lr.iterations;
  report.linear_residual = std::max(report.linear_residual, lr.relative_residual);
  report.solver_fallbacks += lr.used_fallback ? 1 : 0;
  report.converged = report.converged && lr.converged;
}

}  // namespace

Simulation::Simulation(const TetMesh& mesh, std::vector<std::unique_ptr<ForceTerm>> terms,
                       IntegratorSettings settings, std::unique_ptr<LinearSolver> solver)
    : mesh_(mesh), terms_(std::move(terms)), settings_(settings), solver_(std::move(solver)) {
  const int n = mesh.num_nodes();
  x_.resize(3 * n);
  for (int i = 0; i < n; ++i) x_.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  v_ = Eigen::VectorXd::Zero(3 * n);
  mass_ = Eigen::VectorXd::Zero(n);
  if (settings_.kind == IntegratorKind::kBackwardEuler) mass_ = LumpedNodeMass(mesh);
  std::vector<std::pair<int, int>> pairs;
  constant_matrix_ = true;
  for (const auto& term : terms_) {
    term->AppendCoupledNodes(pairs);
    constant_matrix_ = constant_matrix_ && term->JacobianIsConstant();
    if (!elastic_) elastic_ = dynamic_cast<ElasticTetForce*>(term.get());
  }
  matrix_.Build(n, pairs);
  for (const auto& term : terms_) term->BindMatrix(matrix_);
  force_ = Eigen::VectorXd::Zero(3 * n);
  delta_ = Eigen::VectorXd::Zero(3 * n);
}

void Simulation::Assemble(const SystemState& s, double ks, double kd, bool with_matrix, bool k_times_v) {
  force_.setZero(x_.size());
  JacobianSink sink{&matrix_, ks, kd};
  if (k_times_v) {
    k_times_v_.setZero(x_.size());
    sink.velocity = &s.v_m_s;
    sink.stiffness_times_velocity = &k_times_v_;
  }
  if (with_matrix) matrix_.SetZero();
  for (const auto& term : terms_) term->AddForce(s, force_, with_matrix ? &sink : nullptr);
}

void Simulation::PrepareSolver() {
  if (solver_->wants_node_rotations() && elastic_) {
    elastic_->ComputeNodeRotations(node_rotations_);
    solver_->SetNodeRotations(&node_rotations_);
  }
  solver_->Prepare(matrix_);
}

StepReport Simulation::Step(double dt) {
  // The step's start state: kept once per step (no allocation after the first) for the
  // rollback below and as x0, v0 of the backward Euler step.
  x_start_ = x_;
  v_start_ = v_;
  const double t0 = t_;
  StepReport r = settings_.kind == IntegratorKind::kBackwardEuler ? StepBackwardEuler(dt) : StepQuasiStatic(dt);
  r.finite = x_.allFinite() && v_.allFinite();
  if (!r.finite) {
    // Never hand NaN downstream: keep the last good state and say so.
    x_ = x_start_;
    v_ = v_start_;
    t_ = t0 + dt;
    r.converged = false;
  }
  const SystemState s{x_, v_, t_, settings_.kind == IntegratorKind::kBackwardEuler};
  for (const auto& term : terms_) term->EndStep(s);
  r.t_s = t_;
  r.inverted_elements = elastic_ ? elastic_->inverted_elements() : 0;
  return r;
}

StepReport Simulation::StepBackwardEuler(double h) {
  // Newton on g(v1) = M (v1 - v0) - h f(x0 + h v1, v1) = 0. The first iteration is the
  // classic linearized step (Baraff & Witkin): forces, Jacobians and the contact set are
  // taken at the current state (x0, v0), giving (M + hD + h^2 K) dv = h f0 - h^2 K v0.
  // (Linearizing at the predictor x0 + h v0 instead lets a fast-moving contact patch
  // flip in and out of contact every step.) Later iterations re-linearize at x0 + h v1.
  StepReport report;
  const double t1 = t_ + h;
  const Eigen::VectorXd& x0 = x_start_;
  const Eigen::VectorXd& v0 = v_start_;
  v1_ = v0;
  Eigen::VectorXd& v1 = v1_;
  for (int it = 0; it < std::max(1, settings_.newton_iterations); ++it) {
    const bool build = !(constant_matrix_ && matrix_ready_ && matrix_dt_ == h);
    // With a constant matrix the problem is linear and both linearizations coincide.
    const bool at_current_state = it == 0 && build;
    if (at_current_state) x_ = x0;
    else x_ = x0 + h * v1;
    const SystemState s{x_, v1, t1, true};
    Assemble(s, h * h, h, build, at_current_state);
    if (build) {
      for (int i = 0; i < mesh_.num_nodes(); ++i)
        matrix_.AddScaledIdentity(matrix_.DiagonalSlot(i), mass_[i] * (1.0 + h * settings_.rayleigh_alpha_1_s));
      if (!matrix_ready_ && solver_->wants_node_rotations()) solver_->SetReferenceMatrix(matrix_);
      PrepareSolver();
      matrix_ready_ = true;
      matrix_dt_ = h;
    }
    rhs_.resize(x_.size());
    for (int i = 0; i < mesh_.num_nodes(); ++i) {
      const double m = mass_[i];
      rhs_.segment<3>(3 * i) = h * (force_.segment<3>(3 * i) - settings_.rayleigh_alpha_1_s * m * v1.segment<3>(3 * i)) -
                               m * (v1.segment<3>(3 * i) - v0.segment<3>(3 * i));
    }
    if (at_current_state) rhs_ -= h * h * k_times_v_;
    const LinearSolveReport lr = solver_->Solve(matrix_, rhs_, delta_);
    AddNewtonIteration(lr, report);
    v1 += delta_;
    report.max_step_m = h * delta_.cwiseAbs().maxCoeff();
  }
  v_ = v1;
  x_ = x0 + h * v1;
  t_ = t1;
  return report;
}

StepReport Simulation::StepQuasiStatic(double dt) {
  StepReport report;
  const double t1 = t_ + dt;
  const Eigen::VectorXd zero_v = Eigen::VectorXd::Zero(x_.size());
  bool newton_converged = false;
  const int max_it = std::max(1, settings_.newton_iterations);
  for (int it = 0; it < max_it; ++it) {
    const SystemState s{x_, zero_v, t1, false};
    const bool build = !(constant_matrix_ && matrix_ready_);
    Assemble(s, 1.0, 0.0, build);
    if (build) {
      if (!matrix_ready_ && solver_->wants_node_rotations()) solver_->SetReferenceMatrix(matrix_);
      PrepareSolver();
      matrix_ready_ = true;
    }
    delta_.setZero(x_.size());
    const LinearSolveReport lr = solver_->Solve(matrix_, force_, delta_);
    AddNewtonIteration(lr, report);
    x_ += delta_;
    report.max_step_m = delta_.cwiseAbs().maxCoeff();
    if (constant_matrix_) {  // linear problem: one exact solve is the equilibrium
      newton_converged = lr.converged;
      break;
    }
    if (!(report.max_step_m > settings_.newton_tolerance_m)) {
      newton_converged = report.max_step_m <= settings_.newton_tolerance_m;
      break;
    }
  }
  report.converged = report.converged && newton_converged;
  v_.setZero();
  t_ = t1;
  return report;
}

double Simulation::KineticEnergy() const {
  double e = 0;
  for (int i = 0; i < mesh_.num_nodes(); ++i) e += 0.5 * mass_[i] * v_.segment<3>(3 * i).squaredNorm();
  return e;
}

double Simulation::PotentialEnergy() const {
  const SystemState s{x_, v_, t_, true};
  double e = 0;
  for (const auto& term : terms_) e += term->PotentialEnergy(s);
  return e;
}

Eigen::VectorXd Simulation::TotalForce() {
  const SystemState s{x_, Eigen::VectorXd::Zero(x_.size()), t_, false};
  Assemble(s, 1.0, 0.0, false);
  return force_;
}

}  // namespace sedbridge::fem
