#include "bridge/contact_reconstruction.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <unsupported/Eigen/NonLinearOptimization>

#include "common/dynamic_size_functor.h"
#include "sensors/calibration_press.h"

namespace sedbridge::bridge {
namespace {

using sensors::ContactPrimitive;
using sensors::ContactShape;

constexpr double kPi = 3.14159265358979323846;
// Share of the pressing force the taxels' normal channels see (about 0.6 for the uSkin-like
// rig); only used for the first guess of the force.
constexpr double kGuessNormalGain = 0.6;

// Index of log R among a sphere's or rod's unknowns (ToUnknowns).
constexpr int kLogRadius = 2;

int UnknownCount(ContactShape s, bool shear) {
  const int base = s == ContactShape::kFlat ? 1 : 4;
  return base + (shear ? 2 : 0);
}

// Unknowns <-> primitive. Sphere: x, y, log R, log F; cylinder: offset of the axis from
// the pad centre along its normal, yaw, log R, log F; flat: log F; then T_x, T_y [N].
Eigen::VectorXd ToUnknowns(const ContactPrimitive& p, bool shear) {
  Eigen::VectorXd u(UnknownCount(p.shape, shear));
  int i = 0;
  switch (p.shape) {
    case ContactShape::kSphere:
      u[i++] = p.x_mm;
      u[i++] = p.y_mm;
      u[i++] = std::log(p.radius_mm);
      break;
    case ContactShape::kCylinder: {
      const double yaw = p.yaw_deg * kPi / 180;
      u[i++] = -p.x_mm * std::sin(yaw) + p.y_mm * std::cos(yaw);
      u[i++] = yaw;
      u[i++] = std::log(p.radius_mm);
      break;
    }
    case ContactShape::kFlat: break;
  }
  u[i++] = std::log(std::max(p.normal_force_N, 1e-6));
  if (shear) {
    u[i++] = p.shear_x_N;
    u[i++] = p.shear_y_N;
  }
  return u;
}

ContactPrimitive FromUnknowns(ContactShape shape, const Eigen::VectorXd& u, bool shear) {
  ContactPrimitive p;
  p.shape = shape;
  int i = 0;
  switch (shape) {
    case ContactShape::kSphere:
      p.x_mm = u[i++];
      p.y_mm = u[i++];
      p.radius_mm = std::exp(std::clamp(u[i++], -5.0, 6.0));
      break;
    case ContactShape::kCylinder: {
      const double s = u[i++], yaw = u[i++];
      p.x_mm = -s * std::sin(yaw);
      p.y_mm = s * std::cos(yaw);
      // Rods are axes, not arrows: report the yaw in [-90, 90).
      double deg = std::remainder(yaw * 180 / kPi, 180.0);
      if (deg >= 90) deg -= 180;
      p.yaw_deg = deg;
      p.radius_mm = std::exp(std::clamp(u[i++], -5.0, 6.0));
      break;
    }
    case ContactShape::kFlat: p.radius_mm = 0; break;
  }
  p.normal_force_N = std::exp(std::clamp(u[i++], -20.0, 5.0));
  if (shear) {
    p.shear_x_N = u[i++];
    p.shear_y_N = u[i++];
  }
  return p;
}

}  // namespace

struct ContactReconstructor::Fit {
  ContactPrimitive primitive;
  double chi2 = std::numeric_limits<double>::infinity();
  int unknowns = 0;
  int evaluations = 0;
  bool converged = false;  // LM stopped by its own tests, not by a budget or an error
  bool at_radius_bound = false;  // the radius ran out of the plausible range (clamped)
  int budget_used = 0;           // evaluations weighted by patch size
  double Penalized() const { return chi2 + 2.0 * unknowns; }
};

ContactReconstructor::ContactReconstructor(const sensors::SensorProfile& profile, ReconstructionOptions options)
    : profile_(profile),
      options_(options),
      model_(profile.has_forward_model
                 ? sensors::TactileForwardModel(profile, profile.forward_model)
                 : throw std::invalid_argument("sensor profile '" + profile.name +
                                               "' has no forward_model: contact reconstruction needs a calibrated "
                                               "sensor model (sedbridge fit-sensor)")) {
  if (!(options_.min_radius_mm > 0) || !(options_.max_radius_mm > options_.min_radius_mm) ||
      (options_.radius_prior_log_sigma > 0 && !(options_.radius_prior_mm > 0)))
    throw std::invalid_argument("contact reconstruction: need 0 < min_radius_mm < max_radius_mm and radius_prior_mm > 0");
  if (options_.max_hold_scans < 1 || !(options_.hold_change_sigma > 0) || !(options_.hold_force_change_sigma > 0) ||
      options_.cells_per_evaluation < 1 || !(options_.min_chi2_gain >= 0) || !(options_.noise_counts > 0) ||
      options_.scan_evaluations < 0)
    throw std::invalid_argument(
        "contact reconstruction: need max_hold_scans >= 1, hold_change_sigma and hold_force_change_sigma > 0, "
        "cells_per_evaluation >= 1, min_chi2_gain >= 0, noise_counts > 0, scan_evaluations >= 0");
  // A hair inside the plausible range, so that a clamped radius is still plausible.
  log_r_lo_ = std::log(options_.min_radius_mm) + 1e-9;
  log_r_hi_ = std::log(options_.max_radius_mm) - 1e-9;
  const int n = profile.taxel_count;
  inv_sigma_.resize(3 * n);
  full_scale_N_.resize(3 * n);
  const auto& cal = profile.calibration;
  for (int k = 0; k < n; ++k)
    for (int a = 0; a < 3; ++a) {
      const double n_per_count = sensors::NewtonsPerCount(profile, k, a);
      inv_sigma_[3 * k + a] = 1.0 / (options_.noise_counts * n_per_count);
      full_scale_N_[3 * k + a] = (static_cast<double>(cal.saturation_high_counts) - cal.offset_counts[a]) * n_per_count;
    }
}

bool ContactReconstructor::Plausible(const ContactPrimitive& p) const {
  if (!std::isfinite(p.x_mm) || !std::isfinite(p.y_mm) || !std::isfinite(p.normal_force_N) ||
      !std::isfinite(p.shear_x_N) || !std::isfinite(p.shear_y_N))
    return false;
  if (p.shape != ContactShape::kFlat &&
      (p.radius_mm < options_.min_radius_mm || p.radius_mm > options_.max_radius_mm))
    return false;
  return std::hypot(p.x_mm, p.y_mm) <= options_.max_offset_mm;
}

ContactReconstructor::Fit ContactReconstructor::FitShape(ContactShape shape, const ContactPrimitive& start,
                                                         int max_evaluations, int evaluation_budget) const {
  const bool shear = options_.fit_shear;
  // Residuals and their Jacobian. The tangential force enters the forward model linearly,
  // so its two columns are exact and free (PredictLinearInShear). The force column is free
  // too: the patch depends on F and R only through its Hertz half-width (a^3 ~ F R for a
  // sphere, b^2 ~ F R / L for a rod), and the normal part is F times a function of that
  // width, so d pred / d log F = normal part + d pred / d log R (the flat: = normal part).
  // The pose and radius columns are forward differences with NumericalDiff's step
  // (1e-3 |u_j|, or 1e-3 at 0), from the parts already computed at u. A Jacobian costs one
  // model evaluation per pose/radius unknown (3 for spheres and rods, 0 for the flat).
  struct Functor : common::DynamicSizeFunctor {
    const ContactReconstructor* self;
    ContactShape shape;
    bool shear;
    int* evaluations;
    int* budget_used;  // evaluations weighted by patch size (cells_per_evaluation)
    // Radius prior: one more residual, prior_weight (log R - prior_mean), when prior_weight > 0.
    double prior_weight = 0, prior_mean = 0;
    // The model's parts at `at` (the last point evaluated): LM asks df where it just
    // evaluated the residuals.
    mutable Eigen::VectorXd at, normal, per_x, per_y, pred, r_step;
    int inputs() const { return UnknownCount(shape, shear); }
    int values() const { return static_cast<int>(self->obs_.size()) + (prior_weight > 0 ? 1 : 0); }
    void Parts(const Eigen::VectorXd& u) const {
      ++*evaluations;
      int cells = 0;
      self->model_.PredictLinearInShear(FromUnknowns(shape, u, shear), &normal, &per_x, &per_y, &cells);
      *budget_used += std::max(1, cells / std::max(1, self->options_.cells_per_evaluation));
      at = u;
    }
    // Residuals from the parts at `at`, with the tangential force of u.
    void Residuals(const Eigen::VectorXd& u, Eigen::VectorXd& r) const {
      pred = normal;
      if (shear) pred += u[u.size() - 2] * per_x + u[u.size() - 1] * per_y;
      r = (pred - self->obs_).cwiseProduct(self->weight_);
      for (size_t k = 0; k < self->saturated_.size(); ++k)
        if (self->saturated_[k]) {  // at least full scale on the normal axis
          const int c = 3 * static_cast<int>(k) + 2;
          r[c] = std::max(0.0, self->full_scale_N_[c] - pred[c]) * self->inv_sigma_[c];
        }
      if (prior_weight > 0) {
        r.conservativeResize(r.size() + 1);
        r[r.size() - 1] = prior_weight * (u[kLogRadius] - prior_mean);
      }
    }
    int operator()(const Eigen::VectorXd& u, Eigen::VectorXd& r) const {
      Parts(u);
      Residuals(u, r);
      return 0;
    }
    int df(const Eigen::VectorXd& u, Eigen::MatrixXd& J) const {
      const int n = inputs(), geometric = n - (shear ? 2 : 0);
      J.resize(values(), n);
      Eigen::VectorXd r0;
      if (at.size() != u.size() || at != u) Parts(u);
      Residuals(u, r0);
      const Eigen::VectorXd u0 = u, pred0 = pred, normal0 = normal;
      // An analytic column from d pred / d u_j: weighted, a saturated channel's slope where
      // it binds, and 0 in the radius prior's row (only log R, a difference column, moves it).
      auto set_column = [&](int j, const Eigen::VectorXd& d_pred) {
        auto col = J.col(j);
        col.head(d_pred.size()) = d_pred.cwiseProduct(self->weight_);
        if (prior_weight > 0) col[d_pred.size()] = 0;
        for (size_t k = 0; k < self->saturated_.size(); ++k)
          if (self->saturated_[k]) {
            const int c = 3 * static_cast<int>(k) + 2;
            col[c] = self->full_scale_N_[c] - pred0[c] > 0 ? -d_pred[c] * self->inv_sigma_[c] : 0.0;
          }
      };
      if (shear) {  // d pred / d T = per_x, per_y
        set_column(geometric, per_x);
        set_column(geometric + 1, per_y);
      }
      const int log_force = geometric - 1;  // ToUnknowns: log F after the pose and radius
      Eigen::VectorXd d_pred_log_r = Eigen::VectorXd::Zero(normal0.size());  // the flat: none
      for (int j = 0; j < log_force; ++j) {
        double h = 1e-3 * std::abs(u0[j]);
        if (h == 0) h = 1e-3;
        Eigen::VectorXd uj = u0;
        uj[j] += h;
        Parts(uj);
        Residuals(uj, r_step);
        J.col(j) = (r_step - r0) / h;
        if (j == kLogRadius) d_pred_log_r = (pred - pred0) / h;
      }
      set_column(log_force, normal0 + d_pred_log_r);
      return 0;
    }
  };
  int evaluations = 0, budget_used = 0;
  Functor f{{}, this, shape, shear, &evaluations, &budget_used, 0, 0, {}, {}, {}, {}, {}, {}};
  if (shape != ContactShape::kFlat && options_.radius_prior_log_sigma > 0) {
    f.prior_weight = 1.0 / options_.radius_prior_log_sigma;
    f.prior_mean = std::log(options_.radius_prior_mm);
  }
  Eigen::LevenbergMarquardt<Functor> lm(f);
  lm.parameters.maxfev = max_evaluations > 0 ? max_evaluations : options_.max_evaluations;
  lm.parameters.xtol = 1e-6;
  lm.parameters.ftol = 1e-8;
  ContactPrimitive s = start;
  s.shape = shape;
  if (shape == ContactShape::kFlat) s.x_mm = s.y_mm = 0;
  Eigen::VectorXd u = ToUnknowns(s, shear);
  // lm.minimize(u), stopped early when the budget is spent.
  Eigen::LevenbergMarquardtSpace::Status status = lm.minimizeInit(u);
  if (status != Eigen::LevenbergMarquardtSpace::ImproperInputParameters) {
    // Also stopped (amortized) when an iteration gains less than min_chi2_gain: the rest
    // is below the noise, and the next scan refines from here.
    double chi2 = lm.fnorm * lm.fnorm;
    bool gained = true;
    do {
      status = lm.minimizeOneStep(u);
      const double next = lm.fnorm * lm.fnorm;
      gained = evaluation_budget <= 0 || !(chi2 - next < options_.min_chi2_gain);
      chi2 = next;
    } while (status == Eigen::LevenbergMarquardtSpace::Running && gained &&
             (evaluation_budget <= 0 || budget_used < evaluation_budget));
  }
  Fit fit;
  fit.converged = status == Eigen::LevenbergMarquardtSpace::RelativeReductionTooSmall ||
                  status == Eigen::LevenbergMarquardtSpace::RelativeErrorTooSmall ||
                  status == Eigen::LevenbergMarquardtSpace::RelativeErrorAndReductionTooSmall ||
                  status == Eigen::LevenbergMarquardtSpace::CosinusTooSmall ||
                  status == Eigen::LevenbergMarquardtSpace::FtolTooSmall ||
                  status == Eigen::LevenbergMarquardtSpace::XtolTooSmall ||
                  status == Eigen::LevenbergMarquardtSpace::GtolTooSmall;
  fit.primitive = FromUnknowns(shape, u, shear);
  // A radius the scans barely determine (thin rods: a patch narrower than the load grid) can
  // drift out of the plausible range; the answer is then the nearest plausible radius (the
  // next scan's warm fit starts there), not a fallback.
  if (shape != ContactShape::kFlat) {
    const double r = std::clamp(fit.primitive.radius_mm, std::exp(log_r_lo_), std::exp(log_r_hi_));
    if (r != fit.primitive.radius_mm) {
      fit.at_radius_bound = true;
      fit.primitive.radius_mm = r;
      u = ToUnknowns(fit.primitive, shear);
    }
  }
  Eigen::VectorXd r;
  f(u, r);
  // The data's chi^2 (the prior's residual is not evidence for model selection or the RMS).
  const auto data = r.head(static_cast<Eigen::Index>(obs_.size()));
  fit.chi2 = data.allFinite() ? data.squaredNorm() : std::numeric_limits<double>::infinity();
  fit.unknowns = UnknownCount(shape, shear);
  fit.evaluations = evaluations;
  fit.budget_used = budget_used;
  return fit;
}

int ContactReconstructor::AverageHold(const Eigen::VectorXd& readings_N, const std::vector<uint8_t>& valid,
                                      const std::vector<uint8_t>& saturated) {
  bool stationary = options_.max_hold_scans > 1 && hold_scans_ > 0 && valid == hold_valid_ &&
                    saturated == hold_saturated_ && hold_mean_N_.size() == readings_N.size();
  if (stationary) {
    double chi2 = 0, sum_z = 0, var_sum_z = 0;
    int count = 0;
    for (Eigen::Index c = 0; c < readings_N.size(); ++c)
      if (weight_[c] > 0) {
        const double d = (readings_N[c] - hold_mean_N_[c]) * inv_sigma_[c];
        chi2 += d * d;
        ++count;
        if (c % 3 == 2) {
          sum_z += readings_N[c] - hold_mean_N_[c];
          var_sum_z += 1.0 / (inv_sigma_[c] * inv_sigma_[c]);
        }
      }
    // Pure noise: (scan - mean of N) has variance (1 + 1/N) sigma^2 per reading. The sum of
    // the normal readings is tested on its own: a press or release moves it coherently
    // (a ramp's step per scan is under a sigma per taxel but several sigma in the sum).
    const double expected = 1.0 + 1.0 / hold_scans_;
    stationary = count > 0 && chi2 / count <= expected * (1.0 + options_.hold_change_sigma * std::sqrt(2.0 / count)) &&
                 sum_z * sum_z <= options_.hold_force_change_sigma * options_.hold_force_change_sigma * expected * var_sum_z;
  }
  if (!stationary) {
    hold_mean_N_ = readings_N;
    hold_valid_ = valid;
    hold_saturated_ = saturated;
    hold_scans_ = 1;
    return 1;
  }
  hold_scans_ = std::min(hold_scans_ + 1, options_.max_hold_scans);
  hold_mean_N_ += (readings_N - hold_mean_N_) / hold_scans_;
  return hold_scans_;
}

const ContactEstimate& ContactReconstructor::Reconstruct(const sensors::Scan& scan) {
  std::vector<uint8_t> saturated(scan.flags.size(), 0);
  for (size_t k = 0; k < scan.flags.size(); ++k) saturated[k] = (scan.flags[k] & sensors::kTaxelSaturated) != 0;
  return Reconstruct(sensors::ScanReadings_N(scan, profile_), scan.valid, saturated);
}

const ContactEstimate& ContactReconstructor::Reconstruct(const Eigen::VectorXd& readings_N,
                                                         const std::vector<uint8_t>& valid,
                                                         const std::vector<uint8_t>& saturated) {
  ++counters_.scans;
  estimate_ = ContactEstimate{};
  const int n = profile_.taxel_count;
  if (readings_N.size() != 3 * n || static_cast<int>(valid.size()) != n) {
    estimate_.problem = "scan size does not match the profile";
    ++counters_.fallbacks;
    return estimate_;
  }
  obs_ = readings_N;
  weight_ = inv_sigma_;
  saturated_.assign(static_cast<size_t>(n), 0);
  int usable = 0;
  for (int k = 0; k < n; ++k) {
    const bool sat = k < static_cast<int>(saturated.size()) && saturated[k];
    const bool finite = std::isfinite(obs_[3 * k]) && std::isfinite(obs_[3 * k + 1]) && std::isfinite(obs_[3 * k + 2]);
    if (sat) {
      saturated_[static_cast<size_t>(k)] = 1;
      ++counters_.saturated_taxels;
    }
    if (!valid[static_cast<size_t>(k)] || !finite) {
      weight_.segment(3 * k, 3).setZero();
      obs_.segment(3 * k, 3).setZero();
    }
    if ((valid[static_cast<size_t>(k)] && finite) || sat) ++usable;
  }
  {
    std::vector<uint8_t> usable_taxel(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) usable_taxel[static_cast<size_t>(k)] = weight_[3 * k + 2] > 0;
    estimate_.averaged_scans = AverageHold(obs_, usable_taxel, saturated_);
    if (estimate_.averaged_scans > 1) {
      obs_ = hold_mean_N_;
      weight_ *= std::sqrt(static_cast<double>(estimate_.averaged_scans));
    }
  }
  if (usable < 4) {
    estimate_.problem = "fewer than 4 usable taxels";
    ++counters_.fallbacks;
    have_last_ = false;
    have_candidate_ = false;
    return estimate_;
  }

  // Moments of the normal readings: force, centroid, principal direction.
  double sum_z = 0, mx = 0, my = 0;
  for (int k = 0; k < n; ++k) {
    const double z = weight_[3 * k + 2] > 0 ? std::max(0.0, obs_[3 * k + 2]) : (saturated_[k] ? full_scale_N_[3 * k + 2] : 0);
    sum_z += z;
    mx += z * profile_.taxels[k].x_mm;
    my += z * profile_.taxels[k].y_mm;
  }
  if (sum_z < options_.min_force_N * kGuessNormalGain) {
    ++counters_.no_contact;
    estimate_.ok = true;  // "no contact" is a trustworthy answer
    estimate_.primitive.normal_force_N = 0;
    have_last_ = false;
    have_candidate_ = false;
    explored_ = 0;
    return estimate_;
  }
  estimate_.contact = true;
  ++counters_.fits;
  mx /= sum_z;
  my /= sum_z;
  double sxx = 0, syy = 0, sxy = 0;
  for (int k = 0; k < n; ++k) {
    const double z = weight_[3 * k + 2] > 0 ? std::max(0.0, obs_[3 * k + 2]) : 0;
    const double dx = profile_.taxels[k].x_mm - mx, dy = profile_.taxels[k].y_mm - my;
    sxx += z * dx * dx;
    syy += z * dy * dy;
    sxy += z * dx * dy;
  }
  const double principal_yaw_deg = 0.5 * std::atan2(2 * sxy, sxx - syy) * 180 / kPi;

  // In single-scan noise units whatever the number of scans averaged.
  const double dof = std::max(1.0, static_cast<double>((weight_.array() > 0).count())) * estimate_.averaged_scans;
  auto accept = [&](const Fit& fit, bool warm) {
    estimate_.primitive = fit.primitive;
    estimate_.rms_sigma = std::sqrt(fit.chi2 / dof);
    estimate_.warm_started = warm;
    estimate_.ok = std::isfinite(fit.chi2) && estimate_.rms_sigma <= options_.max_rms_sigma && Plausible(fit.primitive);
    if (!estimate_.ok) {
      estimate_.problem = !Plausible(fit.primitive) ? "fit left the plausible domain" : "residual above max_rms_sigma";
      ++counters_.fallbacks;
      // Amortized selection keeps a plausible best guess to refine while it explores.
      have_last_ = options_.selection == ModelSelection::kAmortized && Plausible(fit.primitive);
      if (have_last_) last_ = fit.primitive;
    } else {
      last_ = fit.primitive;
      have_last_ = true;
    }
  };

  // The model-selection starts: shape, radius, yaw (from the moments of the normal readings).
  ContactPrimitive guess;
  guess.x_mm = mx;
  guess.y_mm = my;
  guess.normal_force_N = sum_z / kGuessNormalGain;
  struct Start {
    ContactShape shape;
    double radius_mm, yaw_deg;
  };
  const Start starts[] = {{ContactShape::kSphere, 3.0, 0},
                          {ContactShape::kCylinder, 1.0, principal_yaw_deg},
                          {ContactShape::kFlat, 0, 0},
                          {ContactShape::kSphere, 10.0, 0},
                          {ContactShape::kCylinder, 3.0, principal_yaw_deg},
                          {ContactShape::kCylinder, 1.5, principal_yaw_deg + 90}};
  constexpr int kStarts = sizeof(starts) / sizeof(starts[0]);
  auto fit_start = [&](const Start& s) {
    ContactPrimitive p = guess;
    p.radius_mm = s.radius_mm;
    p.yaw_deg = s.yaw_deg;
    const Fit fit = FitShape(s.shape, p, options_.explore_evaluations);
    estimate_.evaluations += fit.evaluations;
    return fit;
  };
  auto better = [&](const Fit& a, const Fit& b) {  // a better than b
    return Plausible(a.primitive) && std::isfinite(a.chi2) && (!std::isfinite(b.chi2) || a.Penalized() < b.Penalized());
  };

  const bool amortized = options_.selection == ModelSelection::kAmortized;
  Fit best;
  bool warm_won = false;
  if (have_last_) {
    best = FitShape(last_.shape, last_, 0, amortized ? options_.warm_scan_evaluations : 0);
    estimate_.evaluations += best.evaluations;
    warm_won = Plausible(best.primitive);
    if (!warm_won) best = Fit{};
  }
  const bool settled = warm_won && explored_ >= kStarts && std::sqrt(best.chi2 / dof) <= options_.settle_rms_sigma;
  if (options_.selection == ModelSelection::kFull && !(warm_won && std::sqrt(best.chi2 / dof) <= 0.5 * options_.max_rms_sigma)) {
    // Every start, now.
    for (const Start& s : starts) {
      const Fit fit = fit_start(s);
      if (better(fit, best)) best = fit, warm_won = false;
    }
  } else if (amortized && !settled) {
    // One candidate at a time, rotating through the starts, refined within a budget per
    // scan and continued by the next scan; it replaces the current model as soon as it
    // explains the scan better, and is given up when it converged or spent its share.
    // Without a current model (first touch, or the warm fit left the plausible domain)
    // the candidates get the warm budget too, and the next start is tried while budget
    // is left and nothing explains the scan.
    int budget = options_.candidate_scan_evaluations + (warm_won ? 0 : options_.warm_scan_evaluations);
    // A current model that explains the scan leaves the candidate only the rest of the
    // per-scan total: exploring is then a check that can wait for a cheap (holding) scan.
    if (warm_won && options_.scan_evaluations > 0 && std::sqrt(best.chi2 / dof) <= options_.max_rms_sigma)
      budget = std::min(budget, options_.scan_evaluations - best.budget_used);
    for (int tried = 0; budget > 0 && tried < kStarts; ++tried) {
      if (!have_candidate_) {
        const Start& st = starts[next_start_];
        next_start_ = (next_start_ + 1) % kStarts;
        candidate_ = guess;
        candidate_.shape = st.shape;
        candidate_.radius_mm = st.radius_mm;
        candidate_.yaw_deg = st.yaw_deg;
        candidate_spent_ = 0;
        have_candidate_ = true;
      }
      const Fit fit = FitShape(candidate_.shape, candidate_, options_.explore_evaluations, budget);
      estimate_.evaluations += fit.evaluations;
      budget -= fit.budget_used;
      candidate_ = fit.primitive;
      candidate_spent_ += fit.budget_used;
      // A candidate whose radius runs out of the plausible range is the wrong shape (a rod
      // or sphere growing without bound to explain a flat), and its huge patches are the
      // most expensive evaluations: given up.
      bool done = fit.converged || candidate_spent_ >= options_.candidate_evaluations || !Plausible(fit.primitive) ||
                  !std::isfinite(fit.chi2) || fit.at_radius_bound;
      if (better(fit, best)) best = fit, warm_won = false, done = true;
      if (done) {
        have_candidate_ = false;
        ++explored_;
      }
      // The scan is explained: the rest waits for the next.
      if (std::isfinite(best.chi2) && best.chi2 <= options_.max_rms_sigma * options_.max_rms_sigma * dof) break;
    }
    // Still nothing: the flat, whose evaluations are precomputed unit responses (about a
    // microsecond each), so that a scan between two models is answered, not dropped.
    if (!std::isfinite(best.chi2)) {
      const Fit flat = FitShape(ContactShape::kFlat, guess);
      estimate_.evaluations += flat.evaluations;
      if (better(flat, best)) best = flat;
    }
  }
  counters_.evaluations += estimate_.evaluations;
  if (!std::isfinite(best.chi2)) {
    estimate_.problem = "no shape fitted";
    ++counters_.fallbacks;
    have_last_ = false;  // the candidate (amortized) goes on from its iterate
    return estimate_;
  }
  if (warm_won) ++counters_.warm_fits;
  accept(best, warm_won);
  return estimate_;
}

}  // namespace sedbridge::bridge
