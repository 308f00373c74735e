#pragma once
// A time integrator advances the simulation state by one step (Drake's
// DiscreteTimeIntegrator, SOFA's OdeSolver). Each one lives in its own file:
//  - BackwardEulerIntegrator (fem/backward_euler_integrator.h): dynamics, Newton on the
//    implicit Euler equations (1 iteration = the paper's linearized step);
//  - QuasiStaticNewtonIntegrator (fem/quasi_static_newton_integrator.h): equilibrium per
//    load step, no inertia.
// Both drive the same Newton pieces (fem/newton_system.h): assemble, prepare, solve.
// The state itself stays in Simulation (fem/simulation.h).

#include <Eigen/Core>

#include "common/enum_names.h"
#include "common/stage_times.h"
#include "fem/step_report.h"

namespace sedbridge::fem {

enum class IntegratorKind { kBackwardEuler, kQuasiStatic };
/// "backward_euler", "quasi_static" (scene key dynamics.integrator).
inline const config::EnumNames<IntegratorKind>& NamesOf(IntegratorKind) {
  static const config::EnumNames<IntegratorKind> names{{IntegratorKind::kBackwardEuler, "backward_euler"},
                                                       {IntegratorKind::kQuasiStatic, "quasi_static"}};
  return names;
}

struct IntegratorSettings {
  IntegratorKind kind = IntegratorKind::kBackwardEuler;
  /// Backward Euler: Newton iterations per step (1 = the paper's linearized solve).
  /// Quasi-static: maximum Newton iterations per load step.
  int newton_iterations = 1;
  /// Quasi-static convergence: max |dx| below this [m].
  double newton_tolerance_m = 1e-9;
  /// Mass-proportional Rayleigh damping alpha [1/s] (backward Euler only).
  double rayleigh_alpha_1_s = 0.0;
  /// Backward Euler: a step's first linear solve starts from the last two steps' velocity
  /// changes extrapolated (2 dv_n - dv_n-1: a press's acceleration changes smoothly), not
  /// from the last one's. An iterative solver then needs fewer iterations to its tolerance
  /// while the motion is smooth (docs/lab-notes/2026-11-28-fe-step-speed-later-runs.md,
  /// "the SED's kept columns in single precision").
  bool extrapolate_warm_start = true;
};

/// Positions, velocities (3 * #nodes, stacked per node) and time of the simulation.
struct SimulationState {
  Eigen::VectorXd x_m;
  Eigen::VectorXd v_m_s;
  double t_s = 0;
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  /// Advances `state` by dt [s] (quasi-static: the load parameter t; prescribed motions
  /// are evaluated at the new t). Fills the solver fields of the report; the caller
  /// checks finiteness and runs the terms' EndStep.
  virtual StepReport Step(double dt_s, SimulationState& state) = 0;
  /// True when velocities matter (damping forces are evaluated, EndStep sees dynamics).
  virtual bool dynamic() const = 0;
};

}  // namespace sedbridge::fem
