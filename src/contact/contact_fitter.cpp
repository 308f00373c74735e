#include "contact/contact_fitter.h"

#include <algorithm>
#include <cmath>
#include <Eigen/Cholesky>
#include <unsupported/Eigen/NonLinearOptimization>

#include "common/dynamic_size_functor.h"

namespace sedbridge::contact {
namespace {

using sensors::ContactPrimitive;
using sensors::ContactShape;

// The LM functor: one model's residuals in noise units and their Jacobian. The tangential
// force enters the forward model linearly, so its two columns are exact and free
// (PredictLinearInShear). The force column is free
// too: the patch depends on F and R only through its Hertz half-width (a^3 ~ F R for a
// sphere, b^2 ~ F R / L for a rod), and the normal part is F times a function of that
// width, so d pred / d log F = normal part + d pred / d log R (the flat and the punches, rigid
// faces whose pressure keeps its shape as the force grows: = normal part; a punch's half
// sizes are differenced like the pose, 5 evaluations a Jacobian, a round punch's radius 3;
// a corner, whose patch grows with F and which has no radius, differences its force too: 3).
// The pose and radius columns are forward differences with NumericalDiff's step
// (1e-3 |u_j|, or 1e-3 at 0), from the parts already computed at u. A Jacobian costs one
// model evaluation per pose/radius unknown (3 for spheres and rods, 5 for a finite rod,
// 0 for the flat; a finite rod's width depends on F and R only through F R / L too).
// A pair is two spheres whose readings add (the sensor's response is linear in the surface
// load, and two separate patches are that load's sum); the tangential force spreads over
// both patches in proportion to the pressure. Its columns are forward differences too,
// each re-evaluating the one sphere it moves: 8 sphere evaluations a Jacobian.
struct Functor : common::DynamicSizeFunctor {
  const FitProblem* problem;
  ContactShape shape;
  bool pair;
  bool finite;
  bool shear;
  int* evaluations;
  int* budget_used;  // evaluations weighted by patch size (cells_per_evaluation)
  // Radius prior: one more residual per radius, prior_weight (log R - prior_mean), when
  // prior_weight > 0.
  double prior_weight = 0, prior_mean = 0;
  // The model's parts at `at` (the last point evaluated): LM asks df where it just
  // evaluated the residuals. A pair keeps each sphere's.
  mutable Eigen::VectorXd at, normal, per_x, per_y, pred, r_step;
  mutable ModelPart parts[2];
  // Broyden: the last Jacobian of the prediction (d pred / du: the readings' weights and
  // saturated channels do not enter it, so it carries over to the next scan), the point
  // and prediction it belongs to, LM iterations since its finite differences (-1: none).
  int refresh = 1;
  mutable Linearization last{};
  mutable Eigen::MatrixXd Jp{};
  // The parts where the last Jacobian was taken (LM's current point): a rejected trial
  // or the difference columns move `at` away, and the fit's answer is often this point.
  mutable Eigen::VectorXd base_at{}, base_normal{}, base_per_x{}, base_per_y{};
  mutable ModelPart base_parts[2]{};
  // FitBudget::hard_units (0: none): evaluations that would pass it are not started (their
  // cost estimated from the patch they would load), and the call returns -1 (LM stops:
  // UserAsked).
  int hard_units = 0;
  mutable bool stopped = false;
  mutable double refused_units = 0;  // of one evaluation where it stopped
  // Budget units of an evaluation whose patch has `cells` cells.
  double UnitsOf(double cells) const {
    return std::max(1.0, std::floor(cells / std::max(1, problem->options.cells_per_evaluation)));
  }
  // Units of one evaluation at u of the single shape (s < 0) or of a pair's sphere s.
  double Units(const Eigen::VectorXd& u, int s) const {
    const ContactPrimitive c = s < 0 ? ShapeFromUnknowns(shape, finite, u.data())
                                     : ShapeFromUnknowns(ContactShape::kSphere, false, u.data() + s * kSphereUnknowns);
    return UnitsOf(problem->model.PatchCellsEstimate(c));
  }
  // Units of one evaluation of the whole model at u (a pair: both spheres).
  double ModelUnits(const Eigen::VectorXd& u) const { return pair ? Units(u, 0) + Units(u, 1) : Units(u, -1); }
  bool Affordable(const Eigen::VectorXd& u, double evaluations) const {
    if (hard_units <= 0) return true;
    const double units = ModelUnits(u);
    if (*budget_used + evaluations * units <= hard_units) return true;
    stopped = true;
    refused_units = units;
    return false;
  }
  bool Restore(const Eigen::VectorXd& u) const {
    if (base_at.size() != u.size() || base_at != u) return false;
    at = base_at, normal = base_normal, per_x = base_per_x, per_y = base_per_y;
    if (pair) parts[0] = base_parts[0], parts[1] = base_parts[1];
    return true;
  }
  // The parts at u: kept, restored, or evaluated when affordable (false: not).
  bool Ensure(const Eigen::VectorXd& u) const {
    if ((at.size() == u.size() && at == u) || Restore(u)) return true;
    if (!Affordable(u, 1)) return false;
    Parts(u);
    return true;
  }
  int inputs() const { return UnknownCount(shape, pair, finite, shear); }
  int prior_rows() const { return prior_weight > 0 ? (pair ? 2 : 1) : 0; }
  int values() const { return static_cast<int>(problem->obs.size()) + prior_rows(); }
  void EvaluateSphere(int s, const Eigen::VectorXd& u) const {
    ++*evaluations;
    int cells = 0;
    ModelPart& p = parts[s];
    const ContactPrimitive c = ShapeFromUnknowns(ContactShape::kSphere, false, u.data() + s * kSphereUnknowns);
    problem->model.PredictLinearInShear(c, &p.normal, &p.per_x, &p.per_y, &cells);
    p.force_N = c.normal_force_N;
    *budget_used += int(UnitsOf(cells));
  }
  void CombineParts() const {
    const double w = parts[0].force_N / (parts[0].force_N + parts[1].force_N);
    normal = parts[0].normal + parts[1].normal;
    per_x = w * parts[0].per_x + (1 - w) * parts[1].per_x;
    per_y = w * parts[0].per_y + (1 - w) * parts[1].per_y;
  }
  void Parts(const Eigen::VectorXd& u) const {
    if (pair) {
      EvaluateSphere(0, u);
      EvaluateSphere(1, u);
      CombineParts();
    } else {
      ++*evaluations;
      int cells = 0;
      problem->model.PredictLinearInShear(ShapeFromUnknowns(shape, finite, u.data()), &normal, &per_x, &per_y, &cells);
      *budget_used += int(UnitsOf(cells));
    }
    at = u;
  }
  // Residuals from the parts at `at`, with the tangential force of u.
  void Residuals(const Eigen::VectorXd& u, Eigen::VectorXd& r) const {
    pred = normal;
    if (shear) pred += u[u.size() - 2] * per_x + u[u.size() - 1] * per_y;
    r = (pred - problem->obs).cwiseProduct(problem->weight);
    for (size_t k = 0; k < problem->saturated.size(); ++k)
      if (problem->saturated[k]) {  // at least full scale on the normal axis
        const int c = 3 * static_cast<int>(k) + 2;
        r[c] = std::max(0.0, problem->full_scale_N[c] - pred[c]) * problem->inv_sigma[c];
      }
    if (prior_rows() > 0) {
      const Eigen::Index n = r.size();
      r.conservativeResize(n + prior_rows());
      r[n] = prior_weight * (u[kLogRadius] - prior_mean);
      if (pair) r[n + 1] = prior_weight * (u[kSphereUnknowns + kLogRadius] - prior_mean);
    }
  }
  int operator()(const Eigen::VectorXd& u, Eigen::VectorXd& r) const {
    if (!Ensure(u)) return -1;
    Residuals(u, r);
    return 0;
  }
  int df(const Eigen::VectorXd& u, Eigen::MatrixXd& J) const {
    const int n = inputs(), geometric = n - (shear ? 2 : 0);
    J.resize(values(), n);
    Eigen::VectorXd r0;
    if (!Ensure(u)) return -1;
    Residuals(u, r0);
    base_at = u, base_normal = normal, base_per_x = per_x, base_per_y = per_y;
    if (pair) base_parts[0] = parts[0], base_parts[1] = parts[1];
    const Eigen::VectorXd u0 = u, pred0 = pred, normal0 = normal, per_x0 = per_x, per_y0 = per_y;
    // An analytic column from d pred / d u_j: weighted, a saturated channel's slope where
    // it binds, and 0 in the radius prior's rows (only log R, a difference column, moves them).
    auto set_column = [&](int j, const Eigen::VectorXd& d_pred) {
      auto col = J.col(j);
      col.head(d_pred.size()) = d_pred.cwiseProduct(problem->weight);
      col.tail(prior_rows()).setZero();
      for (size_t k = 0; k < problem->saturated.size(); ++k)
        if (problem->saturated[k]) {
          const int c = 3 * static_cast<int>(k) + 2;
          col[c] = problem->full_scale_N[c] - pred0[c] > 0 ? -d_pred[c] * problem->inv_sigma[c] : 0.0;
        }
    };
    auto step = [&](int j) {
      double h = 1e-3 * std::abs(u0[j]);
      return h == 0 ? 1e-3 : h;
    };
    // Column j by a forward difference; returns d pred / d u_j (Parts are then at u0 + h e_j).
    auto difference_column = [&](int j) {
      const double h = step(j);
      Eigen::VectorXd uj = u0;
      uj[j] += h;
      Parts(uj);
      Residuals(uj, r_step);
      J.col(j) = (r_step - r0) / h;
      return Eigen::VectorXd((pred - pred0) / h);
    };
    auto keep = [&] {
      if (pair) return;
      last.jacobian = Jp;
      last.at = u0;
      last.pred = pred0;
    };
    const int n_pred = static_cast<int>(pred0.size());
    Jp.resize(n_pred, n);
    // Broyden for the pose columns only (not a pair's): the radius, which a light scan
    // barely determines, keeps its difference column (with it the free force column), so
    // a poor secant cannot walk it to a bound (the rig's rod press_12 did, to 60 mm).
    const int log_force_column = geometric - 1;
    // A punch's secant covers every geometric column (its force column is the normal part
    // exactly, nothing to difference): a Jacobian for no evaluation, where differences cost
    // five of its largest patches (a 6 x 6 mm face: 700 cells each).
    const bool punch = sensors::IsPunch(shape);
    if (!pair && refresh > 1 && log_force_column > kLogRadius && last.since_differences >= 0 &&
        last.since_differences + 1 < refresh && last.jacobian.rows() == n_pred && last.jacobian.cols() == n &&
        last.at.size() == n) {
      // Secant update of the prediction's Jacobian from where it was last:
      // Jp + (d pred - Jp du) du^T / du^T du; the residuals' columns from it.
      if (!punch && !Affordable(u0, 1)) return -1;  // the radius column
      const Eigen::VectorXd du = u0 - last.at;
      const double dd = du.squaredNorm();
      Jp = last.jacobian;
      if (dd > 0) Jp.noalias() += ((pred0 - last.pred) - last.jacobian * du) * (du.transpose() / dd);
      for (int j = 0; j < log_force_column; ++j)
        if (punch || j != kLogRadius) set_column(j, Jp.col(j));
      if (punch) {
        Jp.col(log_force_column) = normal0;
      } else {
        Jp.col(kLogRadius) = difference_column(kLogRadius);
        Jp.col(log_force_column) = normal0 + Jp.col(kLogRadius);
      }
      set_column(log_force_column, Jp.col(log_force_column));
      if (shear) {
        Jp.col(geometric) = per_x0;
        Jp.col(geometric + 1) = per_y0;
        set_column(geometric, per_x0);
        set_column(geometric + 1, per_y0);
      }
      keep();
      ++last.since_differences;
      return 0;
    }
    // The difference columns: one sphere per column of a pair (four each), else one
    // evaluation per pose/radius column.
    // A corner's patch grows with its force (a^2 ~ F: sensors/cone_pressure.h) and it has no
    // radius to borrow the force column from: that column is a difference too.
    const bool corner = !pair && shape == ContactShape::kCorner;
    if (!Affordable(u0, pair ? kSphereUnknowns : geometric - (corner ? 0 : 1))) return -1;
    last.since_differences = 0;
    if (pair) {
      const ModelPart saved[2] = {parts[0], parts[1]};
      for (int j = 0; j < geometric; ++j) {
        const int s = j / kSphereUnknowns;
        const double h = step(j);
        Eigen::VectorXd uj = u0;
        uj[j] += h;
        EvaluateSphere(s, uj);
        CombineParts();
        Residuals(uj, r_step);
        J.col(j) = (r_step - r0) / h;
        parts[s] = saved[s];
      }
      CombineParts();
      at = u0;
    } else {
      const int log_force = geometric - 1;  // ToUnknowns: log F after the pose and radius
      Eigen::VectorXd d_pred_log_r = Eigen::VectorXd::Zero(normal0.size());  // the flat: none
      for (int j = 0; j < log_force; ++j) {
        Jp.col(j) = difference_column(j);
        if (j == kLogRadius && !sensors::IsPunch(shape)) d_pred_log_r = Jp.col(j);
      }
      if (corner) {
        Jp.col(log_force) = difference_column(log_force);
      } else {
        Jp.col(log_force) = normal0 + d_pred_log_r;
        set_column(log_force, Jp.col(log_force));
      }
    }
    if (shear) {  // d pred / d T = per_x, per_y
      set_column(geometric, per_x0);
      set_column(geometric + 1, per_y0);
      if (!pair) Jp.col(geometric) = per_x0, Jp.col(geometric + 1) = per_y0;
    }
    keep();
    return 0;
  }
};

// The radius prior's residual: on the tracked radius (a single shape's warm fit), else the
// weak one.
void SetRadiusPrior(Functor& f, const ReconstructionOptions& options, double tracked_log_radius,
                    double tracked_log_sigma) {
  const bool tracked = !f.pair && std::isfinite(tracked_log_radius) && tracked_log_sigma > 0;
  const double prior_sigma = tracked ? tracked_log_sigma : options.radius_prior_log_sigma;
  if (sensors::HasFittedRadius(f.shape) && prior_sigma > 0) {
    f.prior_weight = 1.0 / prior_sigma;
    f.prior_mean = tracked ? tracked_log_radius : std::log(options.radius_prior_mm);
  }
}

// Starts from the known parts (the last scan's answer) when u is where they were computed
// (within round-off): u is then exactly that point.
void StartFromKnown(Functor& f, const Prediction* known, Eigen::VectorXd& u) {
  if (known && known->valid && known->shape == f.shape && known->pair == f.pair && known->finite == f.finite &&
      known->at.size() == u.size() &&
      (known->at - u).cwiseAbs().maxCoeff() <= 1e-9 * (1 + u.cwiseAbs().maxCoeff())) {
    u = known->at;
    f.at = known->at;
    f.normal = known->whole.normal;
    f.per_x = known->whole.per_x;
    f.per_y = known->whole.per_y;
    f.parts[0] = known->parts[0];
    f.parts[1] = known->parts[1];
    f.last = known->linearization;
  }
}

// The parts at the functor's last point, when that is the fit's answer.
Prediction PredictionAt(const Functor& f, const Eigen::VectorXd& answer) {
  Prediction p;
  if (f.at.size() != answer.size() || f.at != answer) return p;
  p.valid = true;
  p.shape = f.shape;
  p.pair = f.pair;
  p.finite = f.finite;
  p.at = f.at;
  p.whole = {f.normal, f.per_x, f.per_y, 0.0};
  p.parts[0] = f.parts[0];
  p.parts[1] = f.parts[1];
  p.linearization = f.last;
  return p;
}

Fit ForceStep(const FitProblem& problem, Functor& f, const Eigen::VectorXd& u) {
  // One Gauss-Newton step in (log F, T) with the shape held: three evaluations (the point,
  // its log R difference for the free force column, the step; two when the point's parts
  // are known), where an LM iteration of the whole model costs four and a ramp scan takes
  // three of them.
  Fit fit;
  const Eigen::Index m = problem.obs.size();
  Eigen::VectorXd r0, r1;
  f(u, r0);
  const Eigen::VectorXd pred0 = f.pred, normal0 = f.normal, per_x0 = f.per_x, per_y0 = f.per_y;
  const double h = u[kLogRadius] != 0 ? 1e-3 * std::abs(u[kLogRadius]) : 1e-3;
  Eigen::VectorXd ur = u;
  ur[kLogRadius] += h;
  f(ur, r1);
  const int log_force = static_cast<int>(u.size()) - 3;
  Eigen::MatrixXd A(m, 3);
  A.col(0) = (normal0 + (f.pred - pred0) / h).cwiseProduct(problem.weight);
  A.col(1) = per_x0.cwiseProduct(problem.weight);
  A.col(2) = per_y0.cwiseProduct(problem.weight);
  const Eigen::Vector3d step = (A.transpose() * A).ldlt().solve(-A.transpose() * r0.head(m));
  Eigen::VectorXd u1 = u;
  u1[log_force] += step[0];
  u1[u.size() - 2] += step[1];
  u1[u.size() - 1] += step[2];
  f(u1, r1);
  const double chi2_0 = r0.head(m).squaredNorm(), chi2_1 = r1.head(m).squaredNorm();
  const bool took = step.allFinite() && std::isfinite(chi2_1) && chi2_1 < chi2_0;
  fit.model = FromUnknowns(f.shape, f.pair, f.finite, took ? u1 : u, f.shear);
  if (took) fit.prediction = PredictionAt(f, u1);
  fit.chi2 = took ? chi2_1 : (std::isfinite(chi2_0) ? chi2_0 : std::numeric_limits<double>::infinity());
  fit.unknowns = UnknownCount(f.shape, f.pair, f.finite, f.shear);
  fit.evaluations = *f.evaluations;
  fit.budget_used = *f.budget_used;
  return fit;
}

bool Converged(Eigen::LevenbergMarquardtSpace::Status status) {
  return status == Eigen::LevenbergMarquardtSpace::RelativeReductionTooSmall ||
         status == Eigen::LevenbergMarquardtSpace::RelativeErrorTooSmall ||
         status == Eigen::LevenbergMarquardtSpace::RelativeErrorAndReductionTooSmall ||
         status == Eigen::LevenbergMarquardtSpace::CosinusTooSmall ||
         status == Eigen::LevenbergMarquardtSpace::FtolTooSmall ||
         status == Eigen::LevenbergMarquardtSpace::XtolTooSmall ||
         status == Eigen::LevenbergMarquardtSpace::GtolTooSmall;
}

// LM from u (moved to its answer), within max_evaluations and the budget.
Eigen::LevenbergMarquardtSpace::Status Minimize(const FitProblem& problem, Functor& f, int max_evaluations,
                                                const FitBudget& budget, Eigen::VectorXd& u) {
  Eigen::LevenbergMarquardt<Functor> lm(f);
  lm.parameters.maxfev = max_evaluations > 0 ? max_evaluations : problem.options.max_evaluations;
  lm.parameters.xtol = 1e-6;
  lm.parameters.ftol = 1e-8;
  // lm.minimize(u), stopped early when the budget is spent.
  Eigen::LevenbergMarquardtSpace::Status status = lm.minimizeInit(u);
  if (status != Eigen::LevenbergMarquardtSpace::ImproperInputParameters &&
      status != Eigen::LevenbergMarquardtSpace::UserAsked) {
    // Also stopped (amortized) when an iteration gains less than min_chi2_gain: the rest
    // is below the noise, and the next scan refines from here.
    double chi2 = lm.fnorm * lm.fnorm;
    bool gained = true;
    do {
      status = lm.minimizeOneStep(u);
      const double next = lm.fnorm * lm.fnorm;
      gained = budget.units <= 0 || !(chi2 - next < problem.options.min_chi2_gain);
      chi2 = next;
    } while (status == Eigen::LevenbergMarquardtSpace::Running && gained &&
             (budget.units <= 0 || *f.budget_used < budget.units));
  }
  return status;
}

// The fit at LM's answer u: its radius clamped to the plausible range, its data chi^2 and
// prediction.
Fit Answer(const FitProblem& problem, Functor& f, Eigen::LevenbergMarquardtSpace::Status status, Eigen::VectorXd& u) {
  Fit fit;
  fit.converged = Converged(status);
  fit.model = FromUnknowns(f.shape, f.pair, f.finite, u, f.shear);
  // A radius the scans barely determine (thin rods: a patch narrower than the load grid) can
  // drift out of the plausible range; the answer is then the nearest plausible radius (the
  // next scan's warm fit starts there), not a fallback.
  if (sensors::HasFittedRadius(f.shape)) {
    auto clamp_radius = [&](ContactPrimitive& p) {
      const double r = std::clamp(p.radius_mm, std::exp(problem.log_r_lo), std::exp(problem.log_r_hi));
      if (r != p.radius_mm) fit.at_radius_bound = true, p.radius_mm = r;
    };
    clamp_radius(fit.model.first);
    if (f.pair) clamp_radius(fit.model.second);
    if (fit.at_radius_bound) u = ToUnknowns(fit.model, f.shear);
  }
  fit.unknowns = UnknownCount(f.shape, f.pair, f.finite, f.shear);
  fit.stopped = f.stopped;
  // Stopped before its start was evaluated: nothing known (the start stays the iterate).
  const bool unevaluated = f.stopped && !(f.at.size() == u.size() && f.at == u) && !f.Restore(u);
  if (!unevaluated) {
    Eigen::VectorXd r;
    f.hard_units = 0;  // the answer's parts (kept, or a clamped radius's)
    f(u, r);
    // The data's chi^2 (the prior's residual is not evidence for model selection or the RMS).
    const auto data = r.head(static_cast<Eigen::Index>(problem.obs.size()));
    fit.chi2 = data.allFinite() ? data.squaredNorm() : std::numeric_limits<double>::infinity();
    fit.prediction = PredictionAt(f, u);
  }
  if (!f.pair && sensors::HasFittedRadius(f.shape))
    fit.radius_prior_weight = f.prior_weight;
  fit.evaluations = *f.evaluations;
  fit.budget_used = *f.budget_used;
  fit.refused_units = f.refused_units;
  return fit;
}

}  // namespace

Fit FitModel(const FitProblem& problem, const Hypothesis& start, int max_evaluations, const FitBudget& budget,
             FitMode mode, const Prediction* known, double tracked_log_radius, double tracked_log_sigma) {
  const bool shear = problem.options.fit_shear;
  const bool pair = start.pair;
  const ContactShape shape = pair ? ContactShape::kSphere : start.first.shape;
  const bool finite = !pair && IsFiniteRod(start.first);
  int evaluations = 0, budget_used = 0;
  Functor f{{}, &problem, shape, pair, finite, shear, &evaluations, &budget_used, 0, 0, {}, {}, {}, {}, {}, {}, {}};
  f.refresh = problem.options.jacobian_refresh;
  f.hard_units = budget.hard_units;
  SetRadiusPrior(f, problem.options, tracked_log_radius, tracked_log_sigma);
  Hypothesis s = start;
  s.first.shape = shape;
  if (shape == ContactShape::kFlat) s.first.x_mm = s.first.y_mm = 0;
  Eigen::VectorXd u = ToUnknowns(s, shear);
  StartFromKnown(f, known, u);
  if (mode == FitMode::kForceStep) return ForceStep(problem, f, u);
  const Eigen::LevenbergMarquardtSpace::Status status = Minimize(problem, f, max_evaluations, budget, u);
  return Answer(problem, f, status, u);
}

}  // namespace sedbridge::contact
