#pragma once
// The FE model in time: state (x, v), lumped mass, the force terms a scene asked for, a
// time integrator (backward Euler or quasi-static Newton) and a linear solver.
// Stages of one step (MuJoCo-style split): evaluate terms -> assemble -> solve -> update
// -> EndStep hooks.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "common/enum_names.h"
#include "fem/elastic_tet_force.h"
#include "fem/force_term.h"
#include "fem/linear_solver.h"
#include "fem/system_matrix.h"

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
};

struct StepReport {
  double t_s = 0;
  int newton_iterations = 0;
  int linear_iterations = 0;     ///< summed over Newton iterations
  double linear_residual = 0;    ///< worst relative residual
  int solver_fallbacks = 0;      ///< PCG fallbacks to the direct solver in this step
  bool converged = true;         ///< linear solves and (quasi-static) Newton converged
  int inverted_elements = 0;     ///< det F <= 0 at the end of the step
  double max_step_m = 0;         ///< max |dx| of the last Newton iteration
  bool finite = true;            ///< state is free of NaN/Inf (else it was rolled back)
};

class Simulation {
 public:
  /// @param mesh     rest mesh (must outlive the simulation)
  /// @param terms    force terms, evaluated in this order (contact before friction)
  /// @param settings integrator
  /// @param solver   linear solver
  Simulation(const TetMesh& mesh, std::vector<std::unique_ptr<ForceTerm>> terms, IntegratorSettings settings,
             std::unique_ptr<LinearSolver> solver);

  /// Advances time by dt (quasi-static: the load parameter t; prescribed motions are
  /// evaluated at the new t). A step that produces NaN/Inf is rolled back and reported.
  StepReport Step(double dt_s);

  const Eigen::VectorXd& positions_m() const { return x_; }
  const Eigen::VectorXd& velocities_m_s() const { return v_; }
  void SetPositions(const Eigen::VectorXd& x_m) { x_ = x_m; }
  void SetVelocities(const Eigen::VectorXd& v_m_s) { v_ = v_m_s; }
  double time_s() const { return t_; }
  const TetMesh& mesh() const { return mesh_; }
  const Eigen::VectorXd& node_mass_kg() const { return mass_; }
  const IntegratorSettings& settings() const { return settings_; }
  const LinearSolver& solver() const { return *solver_; }

  /// The elastic term if the scene has one.
  const ElasticTetForce* elastic() const { return elastic_; }
  const std::vector<std::unique_ptr<ForceTerm>>& terms() const { return terms_; }
  /// First term of type T, or null.
  template <typename T>
  T* Find() const {
    for (const auto& t : terms_)
      if (auto* p = dynamic_cast<T*>(t.get())) return p;
    return nullptr;
  }

  double KineticEnergy() const;
  double PotentialEnergy() const;
  /// Sum of all term forces at the current state [N] (equilibrium residual when static).
  Eigen::VectorXd TotalForce();
  /// True if every term's Jacobian is constant (system matrix assembled once).
  bool constant_matrix() const { return constant_matrix_; }


 private:
  /// Forces at s (into force_) and, with_matrix, the system matrix; with k_times_v, also
  /// K v of s's velocity (into k_times_v_).
  void Assemble(const SystemState& s, double stiffness_scale, double damping_scale, bool with_matrix,
                bool k_times_v = false);
  StepReport StepBackwardEuler(double dt);
  StepReport StepQuasiStatic(double dt);
  void PrepareSolver();

  const TetMesh& mesh_;
  std::vector<std::unique_ptr<ForceTerm>> terms_;
  IntegratorSettings settings_;
  std::unique_ptr<LinearSolver> solver_;
  ElasticTetForce* elastic_ = nullptr;
  SystemMatrix matrix_;
  Eigen::VectorXd x_, v_, mass_, force_, rhs_, delta_, k_times_v_;
  Eigen::VectorXd x_start_, v_start_, v1_;  // per-step work buffers
  std::vector<Eigen::Matrix3d> node_rotations_;
  double t_ = 0;
  bool constant_matrix_ = false;
  bool matrix_ready_ = false;
  double matrix_dt_ = -1;
};

}  // namespace sedbridge::fem
