#include "render/inverse_renderer.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace sedbridge::render {

InverseRenderer::InverseRenderer(DisplayInfluence influence, Eigen::VectorXd max_command, InverseRendererOptions options)
    : influence_(std::move(influence)), max_(std::move(max_command)), options_(options) {
  if (max_.size() != influence_.num_actuators())
    throw std::invalid_argument("inverse renderer: one maximum per actuator");
  if (!max_.allFinite() || (max_.array() < 0).any())
    throw std::invalid_argument("inverse renderer: maxima must be finite and >= 0");
  if (!(options_.sed_floor_Pa > 0) || options_.max_iterations < 1 || !(options_.command_tolerance > 0))
    throw std::invalid_argument("inverse renderer: sed_floor_Pa > 0, max_iterations >= 1, command_tolerance > 0");
  if (!(options_.command_penalty_Pa >= 0)) throw std::invalid_argument("inverse renderer: command_penalty_Pa >= 0");
  // The solve's variables are each actuator's stroke past its offset (a pin's gap to the
  // skin): below it the actuator does nothing, and a solve started there would never move.
  offset_ = influence_.command_offsets();
  box_ = (max_ - offset_).cwiseMax(0.0);
  u_.setZero(max_.size());
  commands_.setZero(max_.size());
  inverse_max_ = (max_.array() > 0).select(max_.cwiseInverse(), 0.0);
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
  target_root_ = ((target_sed_Pa + influence_.preload_sed_Pa()).cwiseMax(0.0) + Eigen::VectorXd::Constant(target_sed_Pa.size(), s0))
                     .cwiseSqrt();
  u_ = u_.cwiseMax(0.0).cwiseMin(box_);  // warm start, inside the box
  double cost = Residuals(u_, true);
  for (int it = 0; it < options_.max_iterations; ++it) {
    result_.iterations = it + 1;
    FreeStep(u_);
    double new_cost = cost;
    previous_ = u_;
    if (!LineSearch(cost, u_, &new_cost)) {
      result_.converged = true;  // no descent along the projected step: stationary
      break;
    }
    cost = new_cost;
    if (((u_ - previous_).array().abs() <= options_.command_tolerance * max_.array()).all()) {
      result_.converged = true;
      break;
    }
    cost = Residuals(u_, true);
  }
  result_.cost = cost;
  result_.at_upper_bound = int((u_.array() >= box_.array() && box_.array() > 0).count());
  commands_ = (u_.array() > 0).select(u_ + offset_, 0.0);
  return commands_;
}

double InverseRenderer::Residuals(const Eigen::VectorXd& u, bool with_jacobian) {
  const double s0 = options_.sed_floor_Pa;
  ++result_.evaluations;
  shifted_ = u + offset_;
  if (with_jacobian)
    influence_.SedAndJacobian(shifted_, sed_, dS_);
  else
    influence_.Sed(shifted_, sed_);
  // S_v(u) >= 0 in exact arithmetic (a sum of non-negative element SEDs); round-off may
  // take a vanishing one below.
  const Eigen::VectorXd root = (sed_.array().max(0.0) + s0).sqrt().matrix();
  r_ = root - target_root_;
  if (with_jacobian) J_ = (0.5 * root.cwiseInverse()).asDiagonal() * dS_;
  return 0.5 * r_.squaredNorm() + 0.5 * options_.command_penalty_Pa * (u.cwiseProduct(inverse_max_)).squaredNorm();
}

void InverseRenderer::FreeStep(const Eigen::VectorXd& u) {
  const Eigen::Index n = u.size();
  gradient_.noalias() = J_.transpose() * r_;
  gradient_ += options_.command_penalty_Pa * u.cwiseProduct(inverse_max_).cwiseProduct(inverse_max_);
  // Free: inside the box, or at a bound the descent direction leaves.
  free_.clear();
  for (Eigen::Index i = 0; i < n; ++i) {
    const bool at_lower = u[i] <= 0 && gradient_[i] > 0;
    const bool at_upper = u[i] >= box_[i] && gradient_[i] < 0;
    if (!at_lower && !at_upper && box_[i] > 0) free_.push_back(int(i));
  }
  step_.setZero(n);
  if (free_.empty()) return;
  const Eigen::Index m = Eigen::Index(free_.size());
  H_.resize(m, m);
  Eigen::VectorXd g(m);
  for (Eigen::Index a = 0; a < m; ++a) {
    g[a] = gradient_[free_[size_t(a)]];
    for (Eigen::Index b = 0; b <= a; ++b)
      H_(a, b) = H_(b, a) = J_.col(free_[size_t(a)]).dot(J_.col(free_[size_t(b)]));
  }
  for (Eigen::Index a = 0; a < m; ++a)
    H_(a, a) += options_.command_penalty_Pa * inverse_max_[free_[size_t(a)]] * inverse_max_[free_[size_t(a)]];
  const double scale = std::max(H_.diagonal().maxCoeff(), 1e-300);
  H_.diagonal().array() += options_.damping * scale;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(H_);
  const Eigen::VectorXd d = ldlt.solve(-g);
  if (!d.allFinite()) {  // a flat direction the damping did not cure: steepest descent
    for (Eigen::Index a = 0; a < m; ++a) step_[free_[size_t(a)]] = -g[a] / scale;
    return;
  }
  for (Eigen::Index a = 0; a < m; ++a) step_[free_[size_t(a)]] = d[a];
}

bool InverseRenderer::LineSearch(double cost, Eigen::VectorXd& u, double* new_cost) {
  double alpha = 1.0;
  for (int k = 0; k < 20; ++k, alpha *= 0.5) {
    trial_ = (u + alpha * step_).cwiseMax(0.0).cwiseMin(box_);
    if ((trial_ - u).lpNorm<Eigen::Infinity>() <= 1e-14 * std::max(1.0, max_.lpNorm<Eigen::Infinity>())) return false;
    const double c = Residuals(trial_, false);
    if (c < cost) {
      u = trial_;
      *new_cost = c;
      return true;
    }
  }
  return false;
}

}  // namespace sedbridge::render
