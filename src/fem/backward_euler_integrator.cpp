#include "fem/backward_euler_integrator.h"

#include <algorithm>

namespace sedbridge::fem {

namespace {
// The mass into the diagonal blocks: one thread's pass over B's 1793 nodes takes tens of
// microseconds, a parallel region a few.
constexpr int kParallelMassMinNodes = 1000;
}  // namespace

BackwardEulerIntegrator::BackwardEulerIntegrator(NewtonSystem& system, const Eigen::VectorXd& node_mass_kg,
                                                 const IntegratorSettings& settings)
    : system_(system),
      mass_(node_mass_kg),
      newton_iterations_(settings.newton_iterations),
      rayleigh_alpha_1_s_(settings.rayleigh_alpha_1_s),
      extrapolate_warm_start_(settings.extrapolate_warm_start),
      delta_(Eigen::VectorXd::Zero(3 * node_mass_kg.size())) {}

StepReport BackwardEulerIntegrator::Step(double h, SimulationState& state) {
  // Newton on g(v1) = M (v1 - v0) - h f(x0 + h v1, v1) = 0. The first iteration is the
  // classic linearized step (Baraff & Witkin): forces, Jacobians and the contact set are
  // taken at the current state (x0, v0), giving (M + hD + h^2 K) dv = h f0 - h^2 K v0.
  // (Linearizing at the predictor x0 + h v0 instead lets a fast-moving contact patch
  // flip in and out of contact every step.) Later iterations re-linearize at x0 + h v1.
  StepReport report;
  const double t1 = state.t_s + h;
  const int num_nodes = int(mass_.size());
  x0_ = state.x_m;
  v0_ = state.v_m_s;
  v1_ = v0_;
  Eigen::VectorXd& x = state.x_m;
  for (int it = 0; it < std::max(1, newton_iterations_); ++it) {
    const bool build = !(system_.constant_matrix() && system_.matrix_ready() && assembled_dt_s_ == h);
    // With a constant matrix the problem is linear and both linearizations coincide.
    const bool at_current_state = it == 0 && build;
    if (at_current_state) x = x0_;
    else x = x0_ + h * v1_;
    const SystemState s{x, v1_, t1, true};
    system_.Assemble(s, h * h, h, build, at_current_state, &report.stage_ms);
    if (build) {
      StageTimer mass_timer(report.stage_ms, Stage::kAssembly);
      SystemMatrix& matrix = system_.matrix();
      // Distinct diagonal blocks; scattered over the matrix (three cache lines a node).
#pragma omp parallel for schedule(static) if (num_nodes >= kParallelMassMinNodes)
      for (int i = 0; i < num_nodes; ++i)
        matrix.AddScaledIdentity(matrix.DiagonalSlot(i), mass_[i] * (1.0 + h * rayleigh_alpha_1_s_));
      mass_timer.Stop();
      system_.PrepareSolver(report.stage_ms);
      assembled_dt_s_ = h;
    }
    const Eigen::VectorXd& force = system_.force_N();
    rhs_.resize(x.size());
    for (int i = 0; i < num_nodes; ++i) {
      const double m = mass_[i];
      rhs_.segment<3>(3 * i) = h * (force.segment<3>(3 * i) - rayleigh_alpha_1_s_ * m * v1_.segment<3>(3 * i)) -
                               m * (v1_.segment<3>(3 * i) - v0_.segment<3>(3 * i));
    }
    if (at_current_state) rhs_ -= h * h * system_.stiffness_times_velocity();
    if (it == 0 && extrapolate_warm_start_ && h_last_s_ == h && h_before_s_ == h)
      delta_ = 2 * dv_last_ - dv_before_;  // the solver drops a guess worse than zero (PcgSolver)
    system_.Solve(rhs_, delta_, report);
    v1_ += delta_;
    report.max_step_m = h * delta_.cwiseAbs().maxCoeff();
  }
  if (extrapolate_warm_start_) {
    dv_before_.swap(dv_last_);
    dv_last_ = v1_ - v0_;
    h_before_s_ = h_last_s_;
    h_last_s_ = h;
  }
  state.v_m_s = v1_;
  x = x0_ + h * v1_;
  state.t_s = t1;
  return report;
}

}  // namespace sedbridge::fem
