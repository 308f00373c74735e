#include "fem/simulation.h"

#include <omp.h>

#include <algorithm>

#include "fem/backward_euler_integrator.h"
#include "fem/lumped_mass.h"
#include "fem/quasi_static_newton_integrator.h"

namespace sedbridge::fem {

Simulation::Simulation(const TetMesh& mesh, std::vector<std::unique_ptr<ForceTerm>> terms,
                       IntegratorSettings settings, std::unique_ptr<LinearSolver> solver)
    : mesh_(mesh), terms_(std::move(terms)), settings_(settings), thread_team_(omp_get_max_threads()) {
  const int n = mesh.num_nodes();
  state_.x_m.resize(3 * n);
  for (int i = 0; i < n; ++i) state_.x_m.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  state_.v_m_s = Eigen::VectorXd::Zero(3 * n);
  mass_ = Eigen::VectorXd::Zero(n);
  for (const auto& term : terms_)
    if (!elastic_) elastic_ = dynamic_cast<const ElasticTetForce*>(term.get());
  system_ = std::make_unique<NewtonSystem>(n, terms_, std::move(solver));
  if (settings_.kind == IntegratorKind::kBackwardEuler) {
    mass_ = LumpedNodeMass(mesh);
    integrator_ = std::make_unique<BackwardEulerIntegrator>(*system_, mass_, settings_);
  } else {
    integrator_ = std::make_unique<QuasiStaticNewtonIntegrator>(*system_, settings_);
  }
}

StepReport Simulation::Step(double dt, const std::function<void()>& after_step) {
  // The step's start state: kept once per step (no allocation after the first) for the
  // rollback below.
  step_start_ = state_;
  ChosenTeamScope team = StepTeam();
  StepReport r = integrator_->Step(dt, state_);
  r.finite = state_.x_m.allFinite() && state_.v_m_s.allFinite();
  if (!r.finite) {
    // Never hand NaN downstream: keep the last good state and say so.
    state_.x_m = step_start_.x_m;
    state_.v_m_s = step_start_.v_m_s;
    state_.t_s = step_start_.t_s + dt;
    r.converged = false;
  }
  const SystemState s{state_.x_m, state_.v_m_s, state_.t_s, integrator_->dynamic()};
  for (const auto& term : terms_) term->EndStep(s);
  r.t_s = state_.t_s;
  r.inverted_elements = elastic_ ? elastic_->inverted_elements() : 0;
  r.threads = team.team();
  if (after_step) after_step();
  team.Record(r.newton_iterations);
  return r;
}

double Simulation::KineticEnergy() const {
  double e = 0;
  for (int i = 0; i < mesh_.num_nodes(); ++i) e += 0.5 * mass_[i] * state_.v_m_s.segment<3>(3 * i).squaredNorm();
  return e;
}

double Simulation::PotentialEnergy() const {
  const SystemState s{state_.x_m, state_.v_m_s, state_.t_s, true};
  double e = 0;
  for (const auto& term : terms_) e += term->PotentialEnergy(s);
  return e;
}

Eigen::VectorXd Simulation::TotalForce() {
  const ChosenTeamScope team = StepTeam();  // a whole assembly: on the step's team, not all cores
  const SystemState s{state_.x_m, Eigen::VectorXd::Zero(state_.x_m.size()), state_.t_s, false};
  system_->Assemble(s, 1.0, 0.0, false);
  return system_->force_N();
}

}  // namespace sedbridge::fem
