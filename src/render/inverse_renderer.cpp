#include "render/inverse_renderer.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace sedbridge::render {

InverseRenderer::InverseRenderer(DisplayInfluence influence, Eigen::VectorXd max_command, InverseRendererOptions options)
    : influence_(std::move(influence)), max_(std::move(max_command)), options_(options) {
  if (max_.size() != influence_.num_actuators())
    throw std::invalid_argument("inverse renderer: one maximum per actuator");
  if (!max_.allFinite() || (max_.array() < 0).any())
    throw std::invalid_argument("inverse renderer: maxima must be finite and >= 0");
  if (!(options_.sed_floor_Pa > 0) || options_.max_iterations < 1 || !(options_.command_tolerance > 0) ||
      options_.max_evaluations < 0)
    throw std::invalid_argument(
        "inverse renderer: sed_floor_Pa > 0, max_iterations >= 1, command_tolerance > 0, max_evaluations >= 0");
  if (!(options_.command_penalty >= 0)) throw std::invalid_argument("inverse renderer: command_penalty >= 0");
  if (!(options_.retract_below >= 0 && options_.retract_below < 1))
    throw std::invalid_argument("inverse renderer: retract_below in [0, 1)");
  // The solve's variables are each actuator's stroke past its offset (a pin's gap to the
  // skin): below it the actuator does nothing, and a solve started there would never move.
  offset_ = influence_.command_offsets();
  box_ = (max_ - offset_).cwiseMax(0.0);
  u_.setZero(max_.size());
  commands_.setZero(max_.size());
  PenaltyWeights();
}

const Eigen::VectorXd& InverseRenderer::Render(const Eigen::VectorXd& target_sed_Pa) {
  result_ = RenderResult{};
  if (target_sed_Pa.size() != influence_.num_vertices() || !target_sed_Pa.allFinite()) {
    // Never render from a field we cannot trust; the limiter sees zeros with the flag.
    result_.fault = true;
    Reset();
    return commands_;
  }
  if (!(target_sed_Pa.array() > 0).any()) {  // nothing to render: exactly zero, no solve
    Reset();
    result_.converged = true;
    return commands_;
  }
  const double s0 = options_.sed_floor_Pa;
  // The total SED asked for, the preload's included, is what cannot be negative: a target
  // may take SED away where the preload had it (the difference of two display states does).
  // Only the vertices the display can change are fitted; the others' residuals are a
  // constant of the cost (most of the layer on a pin display: the nail's side, the tip).
  const Eigen::VectorXd total_root =
      ((target_sed_Pa + influence_.preload_sed_Pa()).cwiseMax(0.0) + Eigen::VectorXd::Constant(target_sed_Pa.size(), s0))
          .cwiseSqrt();
  const Eigen::VectorXd resting_root =
      (influence_.preload_sed_Pa().cwiseMax(0.0) + Eigen::VectorXd::Constant(target_sed_Pa.size(), s0)).cwiseSqrt();
  const std::vector<int>& active = influence_.active_vertices();
  target_root_.resize(Eigen::Index(active.size()));
  fixed_cost_ = 0;
  size_t a = 0;
  for (Eigen::Index v = 0; v < total_root.size(); ++v) {
    if (a < active.size() && active[a] == v) {
      target_root_[Eigen::Index(a++)] = total_root[v];
      continue;
    }
    const double r = resting_root[v] - total_root[v];
    fixed_cost_ += 0.5 * r * r;
  }
  u_ = u_.cwiseMax(0.0).cwiseMin(box_);  // warm start, inside the box
  // The last render ended with the field at its answer evaluated; warm-started there, only
  // the residuals change with the target (the SED and its Jacobian do not): one SED
  // evaluation a scan saved, half the work of a one-iteration render.
  // (u_ is that answer: only Reset moves it between renders, and Reset clears evaluated_.)
  double cost = evaluated_ ? CostAt(u_, sed_, r_) : Residuals(u_, r_, sed_, &J_t_);
  for (int it = 0; it < options_.max_iterations; ++it) {
    result_.iterations = it + 1;
    NormalEquations(u_);
    if (free_.empty()) {  // every command held at a bound by its gradient: stationary
      result_.converged = true;
      break;
    }
    // Converged when even the undamped step promises almost nothing: at the answer every
    // trial step would only be rejected, the damping raised, and the field evaluated again.
    if (PredictedDecrease() <= options_.cost_tolerance * (cost + options_.sed_floor_Pa)) {
      result_.converged = true;
      break;
    }
    // Levenberg-Marquardt with Nielsen's damping update: a rejected trial raises the
    // damping (a shorter step, turned toward the gradient) by a factor that doubles with
    // each rejection; an accepted one lowers it by how well the model predicted the
    // decrease. Kept from scan to scan. Each trial is evaluated with its Jacobian: most are
    // accepted, and an accepted one is then not evaluated twice.
    bool accepted = false, stationary = false;
    double raise = 2.0;
    for (int attempt = 0; attempt < 16 && !accepted && !stationary; ++attempt) {
      if (options_.max_evaluations > 0 && result_.evaluations >= options_.max_evaluations) {
        result_.out_of_evaluations = true;
        break;
      }
      DampedStep();
      trial_ = (u_ + step_).cwiseMax(0.0).cwiseMin(box_);
      stationary = (trial_ - u_).lpNorm<Eigen::Infinity>() <= 1e-14 * std::max(1.0, max_.lpNorm<Eigen::Infinity>());
      if (stationary) break;
      const double c = Residuals(trial_, trial_r_, trial_sed_, &trial_J_t_);
      if (c < cost) {
        accepted = true;
        const double gain = (cost - c) / std::max(ModelDecrease(trial_ - u_), 1e-300);
        const double t = 2.0 * gain - 1.0;
        lambda_ = std::max(lambda_ * std::max(0.1, 1.0 - t * t * t), options_.damping);
        cost = c;
      } else {
        ++result_.rejected_trials;
        lambda_ = std::min(lambda_ * raise, 1e12);
        raise *= 2.0;
      }
    }
    if (result_.out_of_evaluations) break;  // the last accepted commands stand; the next scan goes on
    if (!accepted) {
      result_.converged = true;  // no step lowers the cost: stationary
      break;
    }
    previous_.swap(u_);
    u_ = trial_;
    r_.swap(trial_r_), sed_.swap(trial_sed_), J_t_.swap(trial_J_t_);
    if (((u_ - previous_).array().abs() <= options_.command_tolerance * max_.array()).all()) {
      result_.converged = true;
      break;
    }
  }
  evaluated_ = true;  // sed_ and J_t_ are the field at u_ on every path above
  result_.cost = cost;
  result_.at_upper_bound = int((u_.array() >= box_.array() && box_.array() > 0).count());
  // An actuator with an offset (a pin's gap to the skin) whose stroke is below what a device
  // resolves is retracted, not parked at its offset: a stroke of ~0 would command the whole
  // gap, a pin rising to the skin with nothing asked of it (seen after a press had ended: a
  // stroke of 1e-4 mm held by a converged fit, the command 0.95 mm).
  const Eigen::ArrayXd resolved = (offset_.array() > 0).select(options_.retract_below * max_.array(), 0.0);
  commands_ = (u_.array() > resolved).select(u_ + offset_, 0.0);
  return commands_;
}

void InverseRenderer::AddedSed(Eigen::VectorXd& added_sed_Pa) const {
  added_sed_Pa.setZero(influence_.num_vertices());
  if (!evaluated_) return;  // the last Render returned zeros without a fit
  const std::vector<int>& active = influence_.active_vertices();
  for (std::size_t a = 0; a < active.size(); ++a)
    added_sed_Pa[active[a]] = sed_[Eigen::Index(a)] - influence_.preload_sed_Pa()[active[a]];
}

void InverseRenderer::PenaltyWeights() {
  Eigen::VectorXd sed;
  Eigen::MatrixXd dS_t;
  influence_.ActiveSedAndJacobianT(offset_, sed, dS_t);
  const Eigen::VectorXd scale = (0.5 * (sed.array().max(0.0) + options_.sed_floor_Pa).sqrt().inverse()).matrix();
  Eigen::VectorXd strength = (dS_t * scale.asDiagonal()).rowwise().squaredNorm();
  strength = strength.cwiseProduct(box_).cwiseProduct(box_);
  const double floor = 1e-4 * strength.maxCoeff();
  penalty_weight_.setZero(box_.size());
  for (Eigen::Index i = 0; i < box_.size(); ++i)
    if (box_[i] > 0) penalty_weight_[i] = options_.command_penalty * std::max(strength[i], floor) / (box_[i] * box_[i]);
}

double InverseRenderer::Residuals(const Eigen::VectorXd& u, Eigen::VectorXd& r, Eigen::VectorXd& sed,
                                  Eigen::MatrixXd* J_t) {
  ++result_.evaluations;
  shifted_ = u + offset_;
  if (J_t)
    influence_.ActiveSedAndJacobianT(shifted_, sed, dS_t_);
  else
    influence_.ActiveSed(shifted_, sed);
  const double cost = CostAt(u, sed, r);
  if (J_t) J_t->noalias() = dS_t_ * (0.5 * root_.cwiseInverse()).asDiagonal();
  return cost;
}

double InverseRenderer::CostAt(const Eigen::VectorXd& u, const Eigen::VectorXd& sed, Eigen::VectorXd& r) {
  // S_v(u) >= 0 in exact arithmetic (a sum of non-negative element SEDs); round-off may
  // take a vanishing one below.
  root_ = (sed.array().max(0.0) + options_.sed_floor_Pa).sqrt().matrix();
  r = root_ - target_root_;
  return fixed_cost_ + 0.5 * r.squaredNorm() + 0.5 * u.cwiseProduct(u).dot(penalty_weight_);
}

double InverseRenderer::ModelDecrease(const Eigen::VectorXd& step) const {
  // The Gauss-Newton model's decrease for the step taken (projected onto the box): only
  // the free variables move.
  Eigen::VectorXd s(H0_.rows());
  for (Eigen::Index a = 0; a < s.size(); ++a) s[a] = step[free_[size_t(a)]];
  return -(g_.dot(s) + 0.5 * s.dot(H0_ * s));
}

void InverseRenderer::NormalEquations(const Eigen::VectorXd& u) {
  const Eigen::Index n = u.size();
  gradient_.noalias() = J_t_ * r_;
  gradient_ += u.cwiseProduct(penalty_weight_);
  // Free: inside the box, or at a bound the descent direction leaves.
  free_.clear();
  for (Eigen::Index i = 0; i < n; ++i) {
    const bool at_lower = u[i] <= 0 && gradient_[i] > 0;
    const bool at_upper = u[i] >= box_[i] && gradient_[i] < 0;
    if (!at_lower && !at_upper && box_[i] > 0) free_.push_back(int(i));
  }
  const Eigen::Index m = Eigen::Index(free_.size());
  // J^T J of the free variables: a rank update over the layer's vertices (a symmetric
  // product, not a general one: Eigen runs general products on OpenMP threads, which
  // cost more than the product itself at this size and fight the bridge's own threads).
  H0_.setZero(m, m);
  if (m == n) {
    H0_.selfadjointView<Eigen::Lower>().rankUpdate(J_t_);
  } else {
    J_free_t_.resize(m, J_t_.cols());
    for (Eigen::Index a = 0; a < m; ++a) J_free_t_.row(a) = J_t_.row(free_[size_t(a)]);
    H0_.selfadjointView<Eigen::Lower>().rankUpdate(J_free_t_);
  }
  H0_.triangularView<Eigen::StrictlyUpper>() = H0_.transpose();
  g_.resize(m);
  for (Eigen::Index a = 0; a < m; ++a) {
    g_[a] = gradient_[free_[size_t(a)]];
    H0_(a, a) += penalty_weight_[free_[size_t(a)]];
  }
}

double InverseRenderer::PredictedDecrease() const {
  // The Gauss-Newton model's decrease for its own minimizer (no damping, no bounds):
  // 1/2 g^T H0^-1 g.
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(H0_);
  const Eigen::VectorXd d = ldlt.solve(g_);
  const double decrease = 0.5 * g_.dot(d);
  return std::isfinite(decrease) ? std::abs(decrease) : std::numeric_limits<double>::infinity();
}

void InverseRenderer::DampedStep() {
  const Eigen::Index m = H0_.rows();
  // Marquardt's scaling: each command damped in proportion to its own curvature, plus a
  // floor so that a command the layer does not see takes no step.
  const double floor = std::max(H0_.diagonal().maxCoeff(), 1e-300) * 1e-12;
  H_ = H0_;
  H_.diagonal().array() += lambda_ * (H0_.diagonal().array() + floor);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(H_);
  const Eigen::VectorXd d = ldlt.solve(-g_);
  step_.setZero(box_.size());
  for (Eigen::Index a = 0; a < m; ++a) step_[free_[size_t(a)]] = std::isfinite(d[a]) ? d[a] : 0.0;
}

}  // namespace sedbridge::render
