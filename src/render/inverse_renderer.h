#pragma once
// The display's commands by inverse FE: the command vector u, each entry in [0, max_i],
// whose Merkel SED on the leader's model (render/display_influence.h) is closest to the
// target SED the bridge computed. The renderer proposes; the safety limiter after it
// disposes (display/safety_limiter.h), and the leader-side driver keeps its own limits.
//
// The measure: least squares on square roots of SED, r_v = sqrt(S_v(u) + s0) -
// sqrt(T_v + S_v(0) + s0). SED spans three decades over a press (tens of Pa at its rim,
// thousands at its peak): plain SED residuals would fit the peak alone, relative ones the
// faint rim alone. The square root of SED scales with strain (SED is quadratic in it), so
// the fit weighs the field as the layer's deformation does; s0 keeps it smooth at zero.
// S_v(0) is the preload's own SED: the target is what the object adds, the display
// renders it on top of the pad resting on the display.
//
// The solver: Levenberg-Marquardt with box constraints (projected: a variable at a bound
// whose gradient pushes it outward stays there, the rest take the damped Gauss-Newton
// step, projected onto the box; a trial that does not lower the cost raises the damping),
// warm-started from the last scan's commands (and so their bound set) and damping. A few
// iterations a scan: the target moves little between scans. (A backtracking line search
// on the undamped step spent about 15 SED evaluations an iteration on model B's pin
// displays: the piecewise-linear pins and near-invisible actuators make the full step
// overshoot.)

#include <Eigen/Core>
#include <string>
#include <vector>

#include "render/display_influence.h"

namespace sedbridge::render {

struct InverseRendererOptions {
  /// s0 of the measure [Pa]: SED differences well below it weigh little.
  double sed_floor_Pa = 10.0;
  int max_iterations = 8;
  /// SED evaluations a render may spend, rejected trials included (0: no bound but the
  /// iterations'). A scan's cost is its evaluations (each reads the whole influence); a
  /// render that spends them before a trial is accepted keeps its last accepted commands,
  /// and the damping its rejections raised carries to the next scan, which goes on from
  /// there: the worst scan's work is bounded, not only the typical one's.
  int max_evaluations = 0;
  /// Converged when a step moves no command by more than this fraction of its maximum
  /// (1e-4: far below what a device resolves), or the cost stops falling.
  double command_tolerance = 1e-4;
  /// Converged, too, when the undamped Gauss-Newton step promises to lower the cost by less
  /// than this fraction of it (plus the SED floor).
  double cost_tolerance = 1e-6;
  /// Smallest Levenberg-Marquardt damping (relative to each command's own curvature); the
  /// damping adapts from there, and carries over from scan to scan.
  double damping = 1e-9;
  /// rho of the command penalty 1/2 sum_i w_i u_i^2, w_i = rho s_i / full_i^2, where s_i is
  /// what actuator i at full stroke weighs in the fit (|J_i|^2 full_i^2 at rest, never below
  /// 1e-4 of the strongest actuator's): an actuator the Merkel layer barely sees (a pin at
  /// the pad's rim) is otherwise free to sit anywhere, and an ill-conditioned fit drives it
  /// to its maximum. Relative, so that it weighs alike on a suction hole (a few Pa summed
  /// over the layer) and a pin (thousands); it biases a visible actuator by about rho of its
  /// command.
  double command_penalty = 1e-4;
  /// An actuator with a command offset (a pin's gap) whose stroke past it is below this
  /// fraction of its maximum is commanded 0 (retracted) rather than to its offset.
  double retract_below = 1e-3;
};

struct RenderResult {
  bool fault = false;        ///< non-finite target: every command 0
  bool converged = false;
  bool out_of_evaluations = false;  ///< stopped by max_evaluations (not converged)
  int iterations = 0;
  int evaluations = 0;       ///< SED fields evaluated (line-search trials included)
  int rejected_trials = 0;   ///< trials evaluated and not accepted (the cost did not fall)
  double cost = 0;           ///< 1/2 sum r_v^2 at the answer [Pa]
  int at_upper_bound = 0;    ///< commands at their maximum
};

class InverseRenderer {
 public:
  /// @param influence   the display's influence on the leader's Merkel layer (kept by value)
  /// @param max_command per actuator [command unit], >= 0 (the profile's safety limits)
  /// Throws std::invalid_argument on a size mismatch or a negative/non-finite maximum.
  InverseRenderer(DisplayInfluence influence, Eigen::VectorXd max_command, InverseRendererOptions options = {});

  /// Commands for the target vertex SED [Pa] (#vertices of the influence, in its order).
  /// The SED the display should add to the preloaded pad; where it would take away more than
  /// the preload has, the total asked for counts as 0. A target with no positive entry gives
  /// all zeros; a non-finite entry gives all zeros and `fault`.
  const Eigen::VectorXd& Render(const Eigen::VectorXd& target_sed_Pa);
  const Eigen::VectorXd& commands() const { return commands_; }
  const RenderResult& last() const { return result_; }
  /// The SED [Pa] commands() add to the preloaded pad, per vertex, as the last Render's fit
  /// evaluated it at its answer (no evaluation of its own): 0 off the active vertices, and
  /// everywhere after a Render that returned all zeros without a fit.
  void AddedSed(Eigen::VectorXd& added_sed_Pa) const;
  const DisplayInfluence& influence() const { return influence_; }
  /// Forgets the warm start (the next scan starts from all zeros).
  void Reset() { u_.setZero(), commands_.setZero(), evaluated_ = false; }

 private:
  /// r (residuals), the active vertices' SED and, if J_t is given, the residuals'
  /// transposed Jacobian at u; returns the cost.
  double Residuals(const Eigen::VectorXd& u, Eigen::VectorXd& r, Eigen::VectorXd& sed, Eigen::MatrixXd* J_t);
  /// r and the cost at u from the active vertices' SED there (root_ their square roots).
  double CostAt(const Eigen::VectorXd& u, const Eigen::VectorXd& sed, Eigen::VectorXd& r);
  /// What the Gauss-Newton model promises a step (zero off the free variables) lowers the
  /// cost by.
  double ModelDecrease(const Eigen::VectorXd& step) const;
  /// The variables free at u (inside the box, or at a bound the descent leaves) and their
  /// Gauss-Newton matrix H0_ and gradient g_.
  void NormalEquations(const Eigen::VectorXd& u);
  /// step_: the damped Gauss-Newton step (H0 + lambda diag H0) d = -g on the free
  /// variables, 0 on the others.
  void DampedStep();
  /// penalty_weight_ from the influence's Jacobian at rest (InverseRendererOptions).
  void PenaltyWeights();
  /// What the undamped Gauss-Newton step on the free variables would lower the cost by.
  double PredictedDecrease() const;

  DisplayInfluence influence_;
  Eigen::VectorXd max_;
  InverseRendererOptions options_;
  // u_: each actuator's stroke past its offset (the solve's variables), in [0, box_];
  // commands_: offset + stroke where the stroke is > 0, else 0.
  Eigen::VectorXd offset_, box_, commands_, shifted_;
  Eigen::VectorXd penalty_weight_, u_, previous_, target_root_, sed_, r_, step_, trial_, gradient_;
  // Over the active vertices (DisplayInfluence::active_vertices), transposed: #actuators x
  // #vertices, a contiguous column per vertex.
  Eigen::MatrixXd dS_t_, J_t_, J_free_t_, H_, H0_;
  Eigen::VectorXd trial_r_, trial_sed_;  // the last trial's, swapped in when it is accepted
  Eigen::MatrixXd trial_J_t_;
  double fixed_cost_ = 0;  // 1/2 sum r_v^2 over the vertices no command changes
  Eigen::VectorXd root_;
  // sed_ and J_t_ hold the field at u_ (the last render's answer) when evaluated_.
  bool evaluated_ = false;
  Eigen::VectorXd g_;
  double lambda_ = 1e-6;
  std::vector<int> free_;
  RenderResult result_;
};

}  // namespace sedbridge::render
