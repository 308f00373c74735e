#include "fem/quasi_static_newton_integrator.h"

#include <algorithm>

namespace sedbridge::fem {

QuasiStaticNewtonIntegrator::QuasiStaticNewtonIntegrator(NewtonSystem& system, const IntegratorSettings& settings)
    : system_(system),
      max_newton_iterations_(std::max(1, settings.newton_iterations)),
      newton_tolerance_m_(settings.newton_tolerance_m) {}

StepReport QuasiStaticNewtonIntegrator::Step(double dt, SimulationState& state) {
  StepReport report;
  const double t1 = state.t_s + dt;
  Eigen::VectorXd& x = state.x_m;
  if (zero_v_.size() != x.size()) zero_v_.setZero(x.size());
  const Eigen::VectorXd& zero_v = zero_v_;
  // The predictor (and its bookkeeping) only for a nonlinear system: one solve of a linear
  // one is exact from anywhere. It applies only where this integrator's own previous step
  // ended: a state reset or edited from outside starts from itself.
  const bool predict = !system_.constant_matrix();
  if (predict) step_start_x_m_ = x;  // reused buffer: no allocation after the first step
  const bool continues = predict && last_dt_s_ > 0 && dt > 0 && last_end_x_m_.size() == x.size() &&
                         last_end_x_m_ == x;
  if (continues) x += last_increment_m_ * (dt / last_dt_s_);
  bool newton_converged = false;
  bool definite = false;
  for (int it = 0; it < max_newton_iterations_; ++it) {
    const SystemState s{x, zero_v, t1, false};
    const bool build = !(system_.constant_matrix() && system_.matrix_ready());
    system_.Assemble(s, 1.0, 0.0, build, false, &report.stage_ms);
    if (build) system_.PrepareSolver(report.stage_ms);
    delta_.setZero(x.size());
    LinearSolveReport lr = system_.TrySolve(system_.force_N(), delta_, report.stage_ms);
    if (!lr.converged && build && !definite && system_.UseDefiniteJacobians(true)) {
      // The exact tangent can be indefinite (a Cholesky refuses it): this iteration, and
      // the rest of the step, with the positive definite one.
      definite = true;
      ++report.tangent_fallbacks;
      system_.Assemble(s, 1.0, 0.0, true, false, &report.stage_ms);
      system_.PrepareSolver(report.stage_ms);
      delta_.setZero(x.size());
      lr = system_.TrySolve(system_.force_N(), delta_, report.stage_ms);
    }
    NewtonSystem::Record(lr, report);
    x += delta_;
    report.max_step_m = delta_.cwiseAbs().maxCoeff();
    if (system_.constant_matrix()) {  // linear problem: one exact solve is the equilibrium
      newton_converged = lr.converged;
      break;
    }
    if (!(report.max_step_m > newton_tolerance_m_)) {
      newton_converged = report.max_step_m <= newton_tolerance_m_;
      break;
    }
  }
  if (definite) system_.UseDefiniteJacobians(false);  // the next step tries the exact one again
  report.converged = report.converged && newton_converged;
  if (predict && report.converged && x.allFinite()) {
    last_increment_m_ = x - step_start_x_m_;
    last_end_x_m_ = x;
    last_dt_s_ = dt;
  } else {
    last_dt_s_ = 0;
  }
  state.v_m_s.setZero();
  state.t_s = t1;
  return report;
}

}  // namespace sedbridge::fem
