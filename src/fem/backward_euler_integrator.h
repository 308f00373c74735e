#pragma once
// Backward (implicit) Euler with Newton iterations on the velocity update, lumped mass
// and mass-proportional Rayleigh damping (SOFA's EulerImplicitSolver).

#include <Eigen/Core>

#include "common/no_copy_no_move.h"
#include "fem/integrator.h"
#include "fem/newton_system.h"

namespace sedbridge::fem {

class BackwardEulerIntegrator final : public Integrator {
 public:
  SEDBRIDGE_NO_COPY_NO_MOVE(BackwardEulerIntegrator)

  /// @param system      assembly and solver (kept by reference)
  /// @param node_mass_kg lumped mass per node [kg] (kept by reference)
  /// @param settings    Newton iterations per step, Rayleigh alpha
  BackwardEulerIntegrator(NewtonSystem& system, const Eigen::VectorXd& node_mass_kg, const IntegratorSettings& settings);

  StepReport Step(double dt_s, SimulationState& state) override;
  bool dynamic() const override { return true; }

 private:
  NewtonSystem& system_;
  const Eigen::VectorXd& mass_;
  int newton_iterations_;
  double rayleigh_alpha_1_s_;
  double assembled_dt_s_ = -1;  // the step the matrix M + h D + h^2 K was built for
  bool extrapolate_warm_start_;
  Eigen::VectorXd x0_, v0_, v1_, rhs_, delta_;  // per-step work; delta_ warm-starts the next solve
  // The last two steps' velocity changes v1 - v0 and their time steps [s] (0: no such step
  // yet, so a time step equal to both says both changes are there).
  Eigen::VectorXd dv_last_, dv_before_;
  double h_last_s_ = 0, h_before_s_ = 0;
};

}  // namespace sedbridge::fem
