#pragma once
// Quasi-static Newton: each step finds the equilibrium f(x, t1) = 0 of the load at the new
// load parameter t1 (no inertia, no damping), by Newton iterations on K dx = f.

#include <Eigen/Core>

#include "common/no_copy_no_move.h"
#include "fem/integrator.h"
#include "fem/newton_system.h"

namespace sedbridge::fem {

class QuasiStaticNewtonIntegrator final : public Integrator {
 public:
  SEDBRIDGE_NO_COPY_NO_MOVE(QuasiStaticNewtonIntegrator)

  /// @param system   assembly and solver (kept by reference)
  /// @param settings maximum Newton iterations and the convergence tolerance [m]
  QuasiStaticNewtonIntegrator(NewtonSystem& system, const IntegratorSettings& settings);

  /// Velocities are set to zero. When the state is where the previous step left it, the
  /// Newton iterations start from the previous step's increment extrapolated to this one
  /// (a load path is smooth; CalculiX does the same), not from the previous equilibrium.
  StepReport Step(double dt_s, SimulationState& state) override;
  bool dynamic() const override { return false; }

 private:
  NewtonSystem& system_;
  int max_newton_iterations_;
  double newton_tolerance_m_;
  Eigen::VectorXd delta_;
  Eigen::VectorXd zero_v_;
  // The predictor: this step's start, the previous step's end state and increment.
  Eigen::VectorXd step_start_x_m_;
  Eigen::VectorXd last_end_x_m_;
  Eigen::VectorXd last_increment_m_;
  double last_dt_s_ = 0;
};

}  // namespace sedbridge::fem
