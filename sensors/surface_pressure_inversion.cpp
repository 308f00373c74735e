#include "sensors/surface_pressure_inversion.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "sensors/calibration_press.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::sensors {
namespace {

// A cell's unit load reaches the forward model's finer grid as kSub x kSub equal point loads
// (its cells are about half ours: every fine cell under ours gets a share).
constexpr int kSub = 3;
// Armijo constant and the smallest step of the line search [-].
constexpr int kLineSearchTries = 30;
// A tangential force this many of its own standard deviations or more gets the second pass [-].
constexpr double kShearPassSigma = 3.0;

}  // namespace

SurfacePressureInversion::SurfacePressureInversion(const SensorProfile& profile, SurfacePressureOptions options)
    : SurfacePressureInversion(profile, profile.forward_model, options) {
  if (!profile.has_forward_model)
    throw std::invalid_argument("surface pressure: profile '" + profile.name + "' has no forward_model");
}

SurfacePressureInversion::SurfacePressureInversion(const SensorProfile& profile, const TactileModelParams& params,
                                                   SurfacePressureOptions options)
    : profile_(profile), options_(options) {
  if (profile.axes != 3 || profile.taxels.empty())
    throw std::invalid_argument("surface pressure: needs a three-axis profile with taxels");
  if (!(options_.cell_mm >= 0.1 && options_.cell_mm <= 5) || !(options_.noise_counts > 0) ||
      !(options_.sparsity_sigma >= 0) || !(options_.ridge > 0) || options_.max_iterations < 1 ||
      !(options_.tolerance > 0))
    throw std::invalid_argument(
        "surface pressure: need 0.1 <= cell_mm <= 5, noise_counts > 0, sparsity_sigma >= 0, ridge > 0, "
        "max_iterations >= 1, tolerance > 0");
  const TactileForwardModel model(profile, params);
  const int taxels = profile.taxel_count, m = 3 * taxels;
  // The grid: the pad square, centred on the taxels' centre.
  double cx = 0, cy = 0;
  for (const TaxelPosition& t : profile.taxels) cx += t.x_mm, cy += t.y_mm;
  cx /= double(profile.taxels.size()), cy /= double(profile.taxels.size());
  const double h = options_.cell_mm;
  grid_n_ = std::max(1, int(std::ceil(params.pad_size_mm / h - 1e-9)));
  x0_mm_ = cx - 0.5 * (grid_n_ - 1) * h;
  y0_mm_ = cy - 0.5 * (grid_n_ - 1) * h;
  // The forward model's responses to each cell's unit loads.
  const int n = cell_count();
  A_.resize(m, n);
  At_x_.resize(m, n);
  At_y_.resize(m, n);
  const Eigen::Vector2d fine0 = model.CellCentre_mm(0);
  const double hf = model.cell_size_mm();
  const int nf = model.grid_n();
  std::vector<SurfaceLoad> loads;
  Eigen::VectorXd r;
  for (int c = 0; c < n; ++c) {
    const Eigen::Vector2d centre = CellCentre_mm(c);
    loads.clear();
    for (int sy = 0; sy < kSub; ++sy)
      for (int sx = 0; sx < kSub; ++sx) {
        const double x = centre.x() + ((sx + 0.5) / kSub - 0.5) * h, y = centre.y() + ((sy + 0.5) / kSub - 0.5) * h;
        const int i = std::clamp(int(std::lround((x - fine0.x()) / hf)), 0, nf - 1);
        const int j = std::clamp(int(std::lround((y - fine0.y()) / hf)), 0, nf - 1);
        SurfaceLoad l;
        l.cell = i + j * nf;
        l.normal_N = 1.0 / (kSub * kSub);
        loads.push_back(l);
      }
    model.Respond(loads, &r);
    A_.col(c) = r;
    for (auto& l : loads) l.shear_x_N = l.normal_N, l.normal_N = 0;
    model.Respond(loads, &r);
    At_x_.col(c) = r;
    for (auto& l : loads) l.shear_y_N = l.shear_x_N, l.shear_x_N = 0;
    model.Respond(loads, &r);
    At_y_.col(c) = r;
  }
  inv_sigma_.resize(m);
  for (int k = 0; k < taxels; ++k)
    for (int a = 0; a < 3; ++a) inv_sigma_[3 * k + a] = 1.0 / (options_.noise_counts * NewtonsPerCount(profile, k, a));
  // Each cell's unknown is its force times its column's norm in noise units (every taxel
  // valid): the penalties then weigh every cell alike. On forces themselves, the least-norm
  // answer pulls a load towards the taxel centres, where a newton reads the most (0.5 mm off
  // between taxels, the force 8 % high).
  inv_scale_.resize(n);
  for (int c = 0; c < n; ++c) {
    const double norm = A_.col(c).cwiseProduct(inv_sigma_).norm();
    if (!(norm > 0)) throw std::invalid_argument("surface pressure: the forward model reads nothing of a cell");
    inv_scale_[c] = 1.0 / norm;
  }
  A_ = A_ * inv_scale_.asDiagonal();
  At_x_ = At_x_ * inv_scale_.asDiagonal();
  At_y_ = At_y_ * inv_scale_.asDiagonal();
  mu_scale_ = 1.0;
  lambda_ = options_.ridge;
  {
    const Eigen::MatrixXd Aw = inv_sigma_.asDiagonal() * A_;
    Eigen::MatrixXd M = Eigen::MatrixXd::Identity(m, m);
    M.selfadjointView<Eigen::Lower>().rankUpdate(Aw, 1.0 / lambda_);
    ridge_dual_.compute(M);
  }
  y_ = Eigen::VectorXd::Zero(m);
  result_.cell_force_N = Eigen::VectorXd::Zero(n);
}

Eigen::Vector2d SurfacePressureInversion::CellCentre_mm(int cell) const {
  return {x0_mm_ + (cell % grid_n_) * options_.cell_mm, y0_mm_ + (cell / grid_n_) * options_.cell_mm};
}

Eigen::VectorXd SurfacePressureInversion::Predict(const Eigen::VectorXd& cell_force_N, const Eigen::Vector2d& shear_N) const {
  const Eigen::VectorXd u = cell_force_N.cwiseQuotient(inv_scale_);
  return PredictScaled(u, shear_N);
}

Eigen::VectorXd SurfacePressureInversion::PredictScaled(const Eigen::VectorXd& u, const Eigen::Vector2d& shear_N) const {
  Eigen::VectorXd r = A_ * u;
  const double total = u.dot(inv_scale_);
  if (total > 0) r += (At_x_ * u) * (shear_N.x() / total) + (At_y_ * u) * (shear_N.y() / total);
  return r;
}

int SurfacePressureInversion::SolvePass(const Eigen::VectorXd& w, const Eigen::VectorXd& target_N) {
  // Dual: psi(y) = 1/2 |y|^2 + 1/(2 lambda) |max(0, A~^T y - mu)|^2 - r~^T y, A~ = W A,
  // r~ = W target; grad = y + A~ g(y) - r~, g(y) = max(0, A~^T y - mu) / lambda.
  const int m = int(target_N.size()), n = cell_count();
  const Eigen::VectorXd rt = w.cwiseProduct(target_N);
  const double mu = options_.sparsity_sigma * mu_scale_;
  auto field = [&](const Eigen::VectorXd& y, Eigen::VectorXd& g) {
    corr_.noalias() = A_.transpose() * w.cwiseProduct(y);
    g = ((corr_.array() - mu).max(0.0) / lambda_).matrix();
  };
  auto psi = [&](const Eigen::VectorXd& y, const Eigen::VectorXd& g) {
    return 0.5 * y.squaredNorm() + 0.5 * lambda_ * g.squaredNorm() - rt.dot(y);
  };
  // Warm start: the last scan's dual, unless it is worse than no load at all (y = r~).
  Eigen::VectorXd y = y_.size() == m ? y_ : Eigen::VectorXd::Zero(m);
  Eigen::VectorXd g0;
  field(rt, g0);
  double best = psi(rt, g0);
  Eigen::VectorXd start = rt;
  // The ridge answer without the bound (a linear solve on the precomputed matrix, every taxel
  // valid): its active set is near the answer's, far nearer than no load's.
  if (w == inv_sigma_) {
    const Eigen::VectorXd y_ridge = ridge_dual_.solve(rt);
    field(y_ridge, g0);
    if (const double v = psi(y_ridge, g0); v < best) best = v, start = y_ridge;
  }
  field(y, g_);  // corr_ is y's from here on
  if (best < psi(y, g_)) {
    y = start;
    field(y, g_);
  }
  Eigen::VectorXd grad(m), step(m), c1(n), As_g(m);
  int it = 0;
  for (; it < options_.max_iterations; ++it) {
    // The loaded cells S, the gradient y + A~_S g_S - r~ and the Hessian I + A~_S A~_S^T / lambda.
    active_.clear();
    for (int c = 0; c < n; ++c)
      if (g_[c] > 0) active_.push_back(c);
    As_.resize(m, Eigen::Index(active_.size()));
    As_g.setZero();
    for (size_t k = 0; k < active_.size(); ++k) {
      As_.col(Eigen::Index(k)) = w.cwiseProduct(A_.col(active_[k]));
      As_g += As_.col(Eigen::Index(k)) * g_[active_[k]];
    }
    grad = y + As_g - rt;
    if (grad.squaredNorm() <= options_.tolerance * m) break;
    J_.setIdentity(m, m);
    if (!active_.empty()) J_.selfadjointView<Eigen::Lower>().rankUpdate(As_, 1.0 / lambda_);
    step = -J_.selfadjointView<Eigen::Lower>().llt().solve(grad);
    // Exact line search: psi along y + t step is piecewise quadratic, its derivative
    //   d(t) = a + b t + sum_j max(0, c0_j + t c1_j - mu) c1_j / lambda
    // increasing in t; its root by safeguarded Newton (O(#cells) per try, no product).
    c1.noalias() = A_.transpose() * w.cwiseProduct(step);
    ++evaluations_;
    const double a0 = y.dot(step) - rt.dot(step), b0 = step.squaredNorm();
    auto derivative = [&](double t, double* slope) {
      double d = a0 + b0 * t, s2 = b0;
      for (int j = 0; j < n; ++j) {
        const double v = corr_[j] + t * c1[j] - mu;
        if (v > 0) d += v * c1[j] / lambda_, s2 += c1[j] * c1[j] / lambda_;
      }
      *slope = s2;
      return d;
    };
    double lo = 0, hi = -1, t = 1, slope = 0;
    for (int k = 0; k < kLineSearchTries; ++k) {
      const double d = derivative(t, &slope);
      if (std::abs(d) <= 1e-12 * (std::abs(a0) + 1e-300)) break;
      if (d < 0) lo = t; else hi = t;
      double next = t - d / slope;
      if (hi < 0) {
        next = std::max(next, 2 * t);  // no upper bracket yet: at least double
      } else if (!(next > lo && next < hi)) {
        next = 0.5 * (lo + hi);
      }
      t = next;
    }
    if (!(t > 0) || !std::isfinite(t)) break;
    y += t * step;
    corr_ += t * c1;
    g_ = ((corr_.array() - mu).max(0.0) / lambda_).matrix();
  }
  y_ = y;
  return it;
}

double SurfacePressureInversion::ShearSigma_N(const Eigen::VectorXd& w, double total) const {
  // The least-squares tangential force's standard deviation [N]: 1 / sqrt of the smaller
  // eigenvalue of its normal matrix (noise units).
  Eigen::MatrixXd S(w.size(), 2);
  S.col(0) = w.cwiseProduct(At_x_ * g_) / total;
  S.col(1) = w.cwiseProduct(At_y_ * g_) / total;
  const Eigen::Matrix2d N = S.transpose() * S;
  const double tr = N.trace(), det = N.determinant();
  const double smallest = 0.5 * tr - std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
  return smallest > 0 ? 1.0 / std::sqrt(smallest) : std::numeric_limits<double>::infinity();
}

const SurfacePressure& SurfacePressureInversion::Solve(const Scan& scan) {
  std::vector<uint8_t> valid(scan.valid);
  for (size_t k = 0; k < valid.size() && k < scan.flags.size(); ++k)
    if (scan.flags[k] & kTaxelSaturated) valid[k] = 0;  // a bound, not a reading
  if (scan.num_taxels != profile_.taxel_count || scan.num_axes != 3 || int(valid.size()) != profile_.taxel_count) {
    result_ = SurfacePressure{};
    result_.cell_force_N = Eigen::VectorXd::Zero(cell_count());
    result_.fault = "surface pressure: the scan does not match the profile (taxels, axes)";
    return result_;
  }
  return Solve(ScanReadings_N(scan, profile_), valid);
}

const SurfacePressure& SurfacePressureInversion::Solve(const Eigen::VectorXd& readings_N,
                                                       const std::vector<uint8_t>& valid) {
  const int taxels = profile_.taxel_count, m = 3 * taxels, n = cell_count();
  SurfacePressure& out = result_;
  out = SurfacePressure{};
  out.cell_force_N = Eigen::VectorXd::Zero(n);
  if (readings_N.size() != m || (!valid.empty() && int(valid.size()) != taxels)) {
    out.fault = "surface pressure: " + std::to_string(readings_N.size()) + " readings, the profile has " +
                std::to_string(m);
    return out;
  }
  Eigen::VectorXd w = inv_sigma_, r = readings_N;
  for (int k = 0; k < taxels; ++k) {
    if (!valid.empty() && !valid[size_t(k)]) {
      w.segment<3>(3 * k).setZero();
      r.segment<3>(3 * k).setZero();
      continue;
    }
    if (!r.segment<3>(3 * k).allFinite()) {
      out.fault = "surface pressure: non-finite reading on taxel " + std::to_string(k);
      y_.setZero();  // no warm start from a scan that was never solved
      return out;
    }
  }
  auto debias = [&](const Eigen::VectorXd& weights, const Eigen::VectorXd& target) {
    const Eigen::VectorXd p = weights.cwiseProduct(A_ * g_), t = weights.cwiseProduct(target);
    const double pp = p.squaredNorm();
    if (pp > 0) g_ *= std::max(0.0, t.dot(p) / pp);
  };
  // The tangential force by least squares on every channel, the normal field held.
  auto shear = [&]() {
    Eigen::Vector2d s = Eigen::Vector2d::Zero();
    const double total = g_.dot(inv_scale_);
    if (!(total > 0)) return s;
    Eigen::MatrixXd S(m, 2);
    S.col(0) = w.cwiseProduct(At_x_ * g_) / total;
    S.col(1) = w.cwiseProduct(At_y_ * g_) / total;
    const Eigen::VectorXd res = w.cwiseProduct(r - A_ * g_);
    const Eigen::Matrix2d N = S.transpose() * S;
    if (!(N.determinant() > 0)) return s;
    return Eigen::Vector2d(N.ldlt().solve(S.transpose() * res));
  };
  evaluations_ = 0;
  // Pass 1: every channel, no tangential force (a press; a stroke's shear channels then
  // mislead it a little). The tangential force by least squares on the field.
  out.iterations = SolvePass(w, r);
  debias(w, r);
  Eigen::Vector2d T = shear();
  // Pass 2, only when the tangential force reads above noise: the field again on every
  // channel less the tangential part (a stroke).
  const double total1 = g_.dot(inv_scale_);
  if (total1 > 0 && T.norm() > kShearPassSigma * ShearSigma_N(w, total1)) {
    const Eigen::VectorXd target = r - (At_x_ * g_) * (T.x() / total1) - (At_y_ * g_) * (T.y() / total1);
    out.iterations += SolvePass(w, target);
    debias(w, target);
    T = shear();
    out.second_pass = true;
  }
  out.ok = true;
  out.evaluations = evaluations_;
  out.cell_force_N = g_.cwiseProduct(inv_scale_);
  out.normal_force_N = out.cell_force_N.sum();
  out.shear_N = out.normal_force_N > 0 ? T : Eigen::Vector2d::Zero();
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (int j = 0; j < n; ++j)
    if (g_[j] > 0) c += out.cell_force_N[j] * CellCentre_mm(j), ++out.active_cells;
  out.centroid_mm = out.normal_force_N > 0 ? Eigen::Vector2d(c / out.normal_force_N) : c;
  const Eigen::VectorXd res = w.cwiseProduct(r - PredictScaled(g_, out.shear_N));
  int used = 0;
  for (int i = 0; i < m; ++i) used += w[i] > 0;
  out.rms_sigma = used > 0 ? std::sqrt(res.squaredNorm() / used) : 0;
  return out;
}

}  // namespace sedbridge::sensors
