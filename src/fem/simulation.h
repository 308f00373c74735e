#pragma once
// The FE model in time: state (x, v, t), lumped mass, the force terms a scene asked for and
// the pieces that advance it: a time integrator (fem/integrator.h: backward Euler or
// quasi-static Newton, each in its own file) driving the shared Newton system
// (fem/newton_system.h: assembly, linear solver).
// Stages of one step (MuJoCo-style split): evaluate terms -> assemble -> solve -> update
// -> EndStep hooks.

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/no_copy_no_move.h"
#include "fem/elastic_tet_force.h"
#include "fem/force_term.h"
#include "fem/integrator.h"
#include "fem/linear_solver.h"
#include "fem/newton_system.h"
#include "fem/thread_team.h"

namespace sedbridge::fem {

class Simulation {
 public:
  // The Newton system and the integrator hold references to the terms and the mass.
  SEDBRIDGE_NO_COPY_NO_MOVE(Simulation)

  /// @param mesh     rest mesh (must outlive the simulation)
  /// @param terms    force terms, evaluated in this order (contact before friction)
  /// @param settings integrator
  /// @param solver   linear solver (a warped PCG gets its node rotations at construction,
  ///                 MakeLinearSolver's `rotations`)
  Simulation(const TetMesh& mesh, std::vector<std::unique_ptr<ForceTerm>> terms, IntegratorSettings settings,
             std::unique_ptr<LinearSolver> solver);

  /// Advances time by dt (quasi-static: the load parameter t; prescribed motions are
  /// evaluated at the new t). A step that produces NaN/Inf is rolled back and reported.
  /// With AutoThreadTeam() the step runs with the team ThreadTeamChooser picks between 1
  /// and omp_get_max_threads() at construction (the caller's setting is restored after).
  /// @param after_step  work on the new state that belongs to the step (the scene's Merkel
  ///                    SED): it runs on the same team and counts in the step's cost, so a
  ///                    team that is fast for the solve but slow for it is not kept.
  StepReport Step(double dt_s, const std::function<void()>& after_step = {});

  const Eigen::VectorXd& positions_m() const { return state_.x_m; }
  const Eigen::VectorXd& velocities_m_s() const { return state_.v_m_s; }
  void SetPositions(const Eigen::VectorXd& x_m) { state_.x_m = x_m; }
  double time_s() const { return state_.t_s; }
  const TetMesh& mesh() const { return mesh_; }
  const Eigen::VectorXd& node_mass_kg() const { return mass_; }
  const IntegratorSettings& settings() const { return settings_; }
  const LinearSolver& solver() const { return system_->solver(); }
  /// True when the last step's matrix left the element blocks out (NewtonSystem::matrix_free).
  bool matrix_free() const { return system_->matrix_free(); }
  /// The system matrix of the last assembly with a matrix (quasi-static: the stiffness K
  /// [N/m]; incomplete when matrix_free()).
  const SystemMatrix& system_matrix() const { return system_->matrix(); }

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
  /// The team-size chooser of Step (fem/thread_team.h).
  const ThreadTeamChooser& thread_team() const { return thread_team_; }
  /// A scope on Step's team, for work that stands in for a step (the compliance method's
  /// contact step, which never calls Step) or belongs to one (a whole assembly).
  ChosenTeamScope StepTeam() { return ChosenTeamScope(thread_team_); }
  /// True if every term's Jacobian is constant (system matrix assembled once).
  bool constant_matrix() const { return system_->constant_matrix(); }

 private:
  const TetMesh& mesh_;
  std::vector<std::unique_ptr<ForceTerm>> terms_;
  IntegratorSettings settings_;
  const ElasticTetForce* elastic_ = nullptr;
  Eigen::VectorXd mass_;
  SimulationState state_;
  SimulationState step_start_;  // for the rollback of a non-finite step
  std::unique_ptr<NewtonSystem> system_;
  std::unique_ptr<Integrator> integrator_;
  ThreadTeamChooser thread_team_;
};

}  // namespace sedbridge::fem
