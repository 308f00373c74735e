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

  /// Velocities are set to zero.
  StepReport Step(double dt_s, SimulationState& state) override;
  bool dynamic() const override { return false; }

 private:
  NewtonSystem& system_;
  int max_newton_iterations_;
  double newton_tolerance_m_;
  Eigen::VectorXd delta_;
};

}  // namespace sedbridge::fem
