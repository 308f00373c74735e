#include "contact/contact_reconstruction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "sensors/calibration_press.h"

namespace sedbridge::contact {
namespace {

using sensors::ContactPrimitive;
using sensors::ContactShape;

constexpr double kPi = 3.14159265358979323846;
// Share of the pressing force the taxels' normal channels see (about 0.6 for the uSkin-like
// rig); only used for the first guess of the force.
constexpr double kGuessNormalGain = 0.6;

// A finite rod ends at least this far inside the pad (its axis's chord) [mm].
constexpr double kMinEdgeShortfall_mm = 1.0;

}  // namespace

ContactReconstructor::ContactReconstructor(const sensors::SensorProfile& profile, ReconstructionOptions options)
    : profile_(profile),
      options_(options),
      model_(profile.has_forward_model
                 ? sensors::TactileForwardModel(profile, profile.forward_model)
                 : throw std::invalid_argument("sensor profile '" + profile.name +
                                               "' has no forward_model: contact reconstruction needs a calibrated "
                                               "sensor model (sedbridge fit-sensor)")),
      hold_(options_) {
  if (!(options_.min_radius_mm > 0) || !(options_.max_radius_mm > options_.min_radius_mm) ||
      (options_.radius_prior_log_sigma > 0 && !(options_.radius_prior_mm > 0)))
    throw std::invalid_argument("contact reconstruction: need 0 < min_radius_mm < max_radius_mm and radius_prior_mm > 0");
  if (options_.max_hold_scans < 1 || !(options_.hold_change_sigma > 0) || !(options_.hold_force_change_sigma > 0) ||
      options_.cells_per_evaluation < 1 || options_.jacobian_refresh < 1 || !(options_.min_chi2_gain >= 0) || !(options_.noise_counts > 0))
    throw std::invalid_argument(
        "contact reconstruction: need max_hold_scans >= 1, hold_change_sigma and hold_force_change_sigma > 0, "
        "cells_per_evaluation >= 1, jacobian_refresh >= 1, min_chi2_gain >= 0, noise_counts > 0");
  if (!(options_.min_pair_separation_mm >= 0) || !(options_.min_pair_force_share >= 0 && options_.min_pair_force_share <= 0.5) ||
      !(options_.min_rod_length_mm > 0) || options_.explained_candidate_evaluations < 0 ||
      !(options_.radius_track_log_sigma >= 0) || options_.force_step_max_averaged_scans < 1)
    throw std::invalid_argument(
        "contact reconstruction: need min_pair_separation_mm >= 0, 0 <= min_pair_force_share <= 0.5, "
        "min_rod_length_mm > 0, explained_candidate_evaluations >= 0, radius_track_log_sigma >= 0, "
        "force_step_max_averaged_scans >= 1");
  if (!(options_.dead_reading_share >= 0 && options_.dead_reading_share < 1))
    throw std::invalid_argument("contact reconstruction: need 0 <= dead_reading_share < 1");
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
  if (p.shape == ContactShape::kPunch) {
    for (const double half : p.half_size_mm)
      if (!(half >= kMinPunchHalfSize_mm && half <= kMaxPunchHalfSize_mm)) return false;
  } else if (p.shape == ContactShape::kRoundPunch) {
    if (!(p.radius_mm >= kMinPunchHalfSize_mm && p.radius_mm <= kMaxPunchHalfSize_mm)) return false;
  } else if (p.shape == ContactShape::kCorner) {
    // No size: its angle is the box's.
  } else if (p.shape != ContactShape::kFlat &&
             (p.radius_mm < options_.min_radius_mm || p.radius_mm > options_.max_radius_mm)) {
    return false;
  }
  if (IsFiniteRod(p)) {
    // An edge: at least min_rod_length_mm and its diameter long (a stubby cylinder's patch
    // is a sphere's: a held-out 15 mm sphere was read as a rod of radius 11 mm, 4.9 mm long,
    // whose flat ends then cut into the leader's pad), and ending on the pad (at least 1 mm
    // short of the axis's chord across it; one that crosses the pad is the rod model's,
    // whose two unknowns fewer the model selection would otherwise spend on trimming its ends).
    ContactPrimitive crossing = p;
    crossing.length_mm = 0;
    if (p.length_mm < std::max(options_.min_rod_length_mm, 2 * p.radius_mm) ||
        model_.RodLengthOnPad_mm(p) > model_.RodLengthOnPad_mm(crossing) - kMinEdgeShortfall_mm)
      return false;
  }
  return std::hypot(p.x_mm, p.y_mm) <= options_.max_offset_mm;
}

bool ContactReconstructor::Plausible(const Hypothesis& h) const {
  if (!Plausible(h.first)) return false;
  if (!h.pair) return true;
  if (!Plausible(h.second)) return false;
  const double total = h.first.normal_force_N + h.second.normal_force_N;
  return std::hypot(h.first.x_mm - h.second.x_mm, h.first.y_mm - h.second.y_mm) >= options_.min_pair_separation_mm &&
         std::min(h.first.normal_force_N, h.second.normal_force_N) >= options_.min_pair_force_share * total;
}

FitProblem ContactReconstructor::Problem() const {
  return FitProblem{model_, options_, obs_, weight_, inv_sigma_, full_scale_N_, saturated_, log_r_lo_, log_r_hi_};
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
  if (!LoadScan(readings_N, valid, saturated)) return estimate_;
  const NormalMoments sum = NormalSum();
  if (sum.sum_z < options_.min_force_N * kGuessNormalGain) return NoContact();
  estimate_.contact = true;
  ++counters_.fits;
  Selection s = StartSelection(sum);
  if (have_last_) WarmFit(s);
  const bool settled = s.warm_won && explored_ >= s.starts.count && std::sqrt(s.best.chi2 / s.dof) <= options_.settle_rms_sigma;
  if (options_.selection == ModelSelection::kFull &&
      !(s.warm_won && std::sqrt(s.best.chi2 / s.dof) <= 0.5 * options_.max_rms_sigma))
    SelectFull(s);
  else if (options_.selection == ModelSelection::kAmortized && !settled)
    SelectAmortized(s);
  CheckRoundPunch(s);
  CheckCorner(s);
  counters_.evaluations += estimate_.evaluations;
  if (!std::isfinite(s.best.chi2)) {
    estimate_.problem = "no shape fitted";
    ++counters_.fallbacks;
    FlagInadequate(s.dof);
    have_last_ = false;  // the candidate (amortized) goes on from its iterate
    have_last_chi2_ = false;
    return estimate_;
  }
  if (s.warm_won) ++counters_.warm_fits;
  const bool carried_lone = lone_taxel_ >= 0;
  LeaveOutLoneMisfit(s);
  Accept(s.best, s.warm_won, s.dof);
  if (carried_lone && estimate_.ok) MaybeTakeBackLoneTaxel(s.best);
  FlagInadequate(s.dof);
  return estimate_;
}

double ContactReconstructor::AdequateRms2(double dof) const {
  // A residual within the hold mean's noise (a chi^2 test at adequacy_z) and the model's own
  // error (reconstruction_options.h). dof = m channels x N scans.
  const double n = std::max(1, estimate_.averaged_scans), m = std::max(1.0, dof / n);
  return (1 + options_.adequacy_z * std::sqrt(2 / m)) / n + options_.model_error_sigma * options_.model_error_sigma;
}

void ContactReconstructor::FlagInadequate(double dof) {
  // No model explains the contact within noise: nothing plausible, or a residual above
  // AdequateRms2.
  estimate_.model_inadequate =
      estimate_.contact && !(estimate_.ok && estimate_.rms_sigma * estimate_.rms_sigma <= AdequateRms2(dof));
  if (estimate_.model_inadequate) ++counters_.model_inadequate;
}

bool ContactReconstructor::LoadScan(const Eigen::VectorXd& readings_N, const std::vector<uint8_t>& valid,
                                    const std::vector<uint8_t>& saturated) {
  const int n = profile_.taxel_count;
  if (readings_N.size() != 3 * n || static_cast<int>(valid.size()) != n) {
    estimate_.problem = "scan size does not match the profile";
    ++counters_.fallbacks;
    return false;
  }
  obs_ = readings_N;
  weight_ = inv_sigma_;
  saturated_.assign(static_cast<size_t>(n), 0);
  estimate_.taxel_use.assign(static_cast<size_t>(n), TaxelUse::kLeftOut);
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
    if ((valid[static_cast<size_t>(k)] && finite) || sat) {
      ++usable;
      estimate_.taxel_use[static_cast<size_t>(k)] = sat ? TaxelUse::kSaturated : TaxelUse::kUsed;
    }
  }
  if (lone_taxel_ >= 0 && weight_[3 * lone_taxel_ + 2] > 0 && !saturated_[size_t(lone_taxel_)]) {
    // Still left out: an earlier scan's lone misfit (LeaveOutLoneMisfit).
    weight_.segment(3 * lone_taxel_, 3).setZero();
    estimate_.taxel_use[size_t(lone_taxel_)] = TaxelUse::kLoneMisfit;
    --usable;
    ++counters_.lone_taxel_scans;
  } else {
    lone_taxel_ = -1;
  }
  estimate_.taxels_used = usable;
  {
    std::vector<uint8_t> usable_taxel(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) usable_taxel[static_cast<size_t>(k)] = weight_[3 * k + 2] > 0;
    estimate_.averaged_scans = hold_.Average(obs_, usable_taxel, saturated_, weight_, inv_sigma_);
    if (estimate_.averaged_scans > 1) {
      obs_ = hold_.mean_N();
      weight_ *= std::sqrt(static_cast<double>(estimate_.averaged_scans));
    }
  }
  if (usable < 4) {
    estimate_.problem = "fewer than 4 usable taxels";
    ++counters_.fallbacks;
    have_last_ = false;
    have_last_chi2_ = false;
    have_candidate_ = false;
    lone_taxel_ = -1;
    return false;
  }
  return true;
}

NormalMoments ContactReconstructor::NormalSum() const {
  NormalMoments m;
  const int n = profile_.taxel_count;
  for (int k = 0; k < n; ++k) {
    const double z = weight_[3 * k + 2] > 0 ? std::max(0.0, obs_[3 * k + 2]) : (saturated_[k] ? full_scale_N_[3 * k + 2] : 0);
    m.sum_z += z;
    m.mx += z * profile_.taxels[k].x_mm;
    m.my += z * profile_.taxels[k].y_mm;
  }
  return m;
}

const ContactEstimate& ContactReconstructor::NoContact() {
  ++counters_.no_contact;
  estimate_.ok = true;  // "no contact" is a trustworthy answer
  estimate_.primitive.normal_force_N = 0;
  have_last_ = false;
  have_last_chi2_ = false;
  have_candidate_ = false;
  lone_taxel_ = -1;
  explored_ = 0;
  pair_checked_ = false;
  punch_round_ = false;
  round_punch_ = corner_ = SideCandidate{};
  return estimate_;
}

ContactReconstructor::Selection ContactReconstructor::StartSelection(NormalMoments m) {
  const int n = profile_.taxel_count;
  const double sum_z = m.sum_z;
  m.mx /= sum_z;
  m.my /= sum_z;
  double sxx = 0, syy = 0, sxy = 0;
  for (int k = 0; k < n; ++k) {
    const double z = weight_[3 * k + 2] > 0 ? std::max(0.0, obs_[3 * k + 2]) : 0;
    const double dx = profile_.taxels[k].x_mm - m.mx, dy = profile_.taxels[k].y_mm - m.my;
    sxx += z * dx * dx;
    syy += z * dy * dy;
    sxy += z * dx * dy;
  }
  m.principal_yaw_deg = 0.5 * std::atan2(2 * sxy, sxx - syy) * 180 / kPi;
  // Spread of the normal readings along the principal direction [mm^2].
  m.principal_var_mm2 = (0.5 * (sxx + syy) + std::sqrt(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy)) / sum_z;
  m.minor_var_mm2 = (sxx + syy) / sum_z - m.principal_var_mm2;

  Selection s;
  // In single-scan noise units whatever the number of scans averaged.
  s.dof = std::max(1.0, static_cast<double>((weight_.array() > 0).count())) * estimate_.averaged_scans;
  s.moments = m;
  s.guess.x_mm = m.mx;
  s.guess.y_mm = m.my;
  s.guess.normal_force_N = sum_z / kGuessNormalGain;
  s.starts = MakeStarts(options_, m);
  // A candidate of the last answer's shape is the same object at another size: it is judged
  // with the warm fit's prior on the radius (the last answer's, radius_track_log_sigma)
  // instead of the weak one, as the warm fit is. Otherwise, at light load, where any radius
  // explains a scan within noise, a candidate of another size replaced the model by chance
  // (rig press_03, a 5 mm sphere, at 0.08 N: 12.5 mm for the warm fit's 3 mm, walked back to
  // 5.3 mm by 0.25 N; test RadiusHoldsStillWhileTheContactLoads).
  track_ = TrackRadius(options_, have_last_, last_, last_log_radius_var_, estimate_.averaged_scans);
  s.track_candidates = options_.selection == ModelSelection::kAmortized && std::isfinite(track_.log_radius);
  return s;
}

void ContactReconstructor::LeaveOutLoneMisfit(Selection& s) {
  const Fit& best = s.best;
  if (!(options_.lone_taxel_share > 0) || !best.prediction.valid || !Plausible(best.model)) return;
  const bool falls_back = best.chi2 > options_.max_rms_sigma * options_.max_rms_sigma * s.dof;
  if (!falls_back && !(best.chi2 > AdequateRms2(s.dof) * s.dof)) return;
  // The best fit's residuals per taxel (prediction - reading, in noise units).
  const Eigen::VectorXd r = (Predicted(best) - obs_).cwiseProduct(weight_);
  const int n = profile_.taxel_count;
  // Two candidates: the taxel that carries the most misfit, and the one that reads the most
  // below what the fit predicts. A fit that bent around a dead taxel under the contact
  // (a small sphere moved off it) spreads its misfit over the taxels beside it, which read
  // more than it can explain; the dead one still reads less than predicted, by less.
  int worst = -1, deficit = -1;
  double worst_chi2 = 0, deficit_sigma = 0;
  for (int k = 0; k < n; ++k) {
    if (saturated_[size_t(k)] || !(weight_[3 * k + 2] > 0)) continue;  // a saturated taxel is hard contact
    const double c = r.segment(3 * k, 3).squaredNorm();
    if (c > worst_chi2) worst_chi2 = c, worst = k;
    if (r[3 * k + 2] > deficit_sigma) deficit_sigma = r[3 * k + 2], deficit = k;
  }
  if (!falls_back) {
    // Within max_rms_sigma but inadequate (a dead taxel whose load is small, off the contact,
    // or carried by a hold's mean: rig press_03, a 5 mm sphere at the centre with corner taxel
    // 1 dead, at 2.6 sigma over the hold, where a 2.6 mm punch then won by absorbing it):
    // only the taxel that reads the most below the fit, when the refit without it is adequate
    // and its misfit stands alone.
    // And only a taxel that reads like a dead one, less than dead_reading_share of what the
    // fit predicts for it: a wrong shape's misfit (a sphere on a punch, whose centre is
    // loaded less than a dome's) leaves the taxel most of its predicted reading.
    if (deficit >= 0 && options_.dead_reading_share > 0 &&
        obs_[3 * deficit + 2] <= options_.dead_reading_share * Predicted(best)[3 * deficit + 2])
      RefitWithout(deficit, s, true, true);
    return;
  }
  if (worst >= 0 && worst_chi2 >= options_.lone_taxel_share * best.chi2 && RefitWithout(worst, s, false)) return;
  if (deficit >= 0 && deficit != worst) RefitWithout(deficit, s, true);
}

bool ContactReconstructor::RefitWithout(int k, Selection& s, bool must_stand_alone, bool adequate) {
  const Fit& best = s.best;
  // Refit without it, warm from the best fit (its parts do not depend on the weights).
  const Eigen::VectorXd saved = weight_.segment(3 * k, 3);
  weight_.segment(3 * k, 3).setZero();
  const bool amortized = options_.selection == ModelSelection::kAmortized;
  Fit refit = FitModel(Problem(), best.model, 0, amortized ? options_.warm_scan_evaluations : 0,
                       FitMode::kLevenbergMarquardt, &best.prediction);
  Tally(refit);
  if (IsFiniteRod(refit.model.first) && !refit.model.pair && !Plausible(refit.model)) {
    // A rod that ended short of the taxel (a dead one at its end) reaches across the pad
    // once the taxel is out: the rod across the pad, from the same pose.
    Hypothesis crossing = refit.model;
    crossing.first.length_mm = 0;
    Fit across = FitModel(Problem(), crossing, 0, amortized ? options_.warm_scan_evaluations : 0);
    Tally(across);
    if (across.chi2 < refit.chi2 || !Plausible(refit.model)) refit = std::move(across);
  }
  const double dof = std::max(1.0, s.dof - 3.0 * estimate_.averaged_scans);
  const double within = adequate ? AdequateRms2(dof) : options_.max_rms_sigma * options_.max_rms_sigma;
  bool accept = refit.chi2 <= within * dof && Plausible(refit.model);
  if (accept && must_stand_alone) {
    // Its misfit stands alone: the refit predicts it worse than it explains all the others
    // together (the share rule's counterpart, judged by the fit that left it out).
    const double alone = (Predicted(refit) - obs_).segment(3 * k, 3).cwiseProduct(saved).squaredNorm();
    accept = refit.prediction.valid && alone >= refit.chi2;
  }
  if (!accept) {
    weight_.segment(3 * k, 3) = saved;
    return false;
  }
  s.best = refit;
  s.dof = dof;
  lone_taxel_ = k;
  estimate_.taxel_use[size_t(k)] = TaxelUse::kLoneMisfit;
  --estimate_.taxels_used;
  ++counters_.lone_taxels_left_out;
  return true;
}

Eigen::VectorXd ContactReconstructor::Predicted(const Fit& fit) const {
  const Prediction& p = fit.prediction;
  Eigen::VectorXd pred = p.whole.normal;
  if (options_.fit_shear && p.at.size() >= 2)
    pred += p.at[p.at.size() - 2] * p.whole.per_x + p.at[p.at.size() - 1] * p.whole.per_y;
  return pred;
}

void ContactReconstructor::MaybeTakeBackLoneTaxel(const Fit& fit) {
  if (lone_taxel_ < 0 || !fit.prediction.valid) return;
  const int k = lone_taxel_;
  const Eigen::VectorXd r = (Predicted(fit) - obs_).segment(3 * k, 3).cwiseProduct(inv_sigma_.segment(3 * k, 3));
  if (r.squaredNorm() <= 3 * options_.max_rms_sigma * options_.max_rms_sigma) lone_taxel_ = -1;
}

void ContactReconstructor::Accept(const Fit& fit, bool warm, double dof) {
  estimate_.primitive = fit.model.first;
  estimate_.two_contacts = fit.model.pair;
  if (fit.model.pair) estimate_.second = fit.model.second;
  estimate_.rms_sigma = std::sqrt(fit.chi2 / dof);
  estimate_.warm_started = warm;
  const bool plausible = Plausible(fit.model);
  estimate_.ok = std::isfinite(fit.chi2) && estimate_.rms_sigma <= options_.max_rms_sigma && plausible;
  // The radius's posterior variance goes with last_ (posterior tracking only; computed for
  // the accepted fit alone): this fit's, or (a force step, which holds the shape) the last
  // one's; a new shape without one starts from the weak prior.
  auto keep_radius_variance = [&] {
    if (!options_.radius_track_posterior) return;
    const bool same_shape =
        have_last_ && !last_.pair && !fit.model.pair && last_.first.shape == fit.model.first.shape;
    const double variance = LogRadiusVariance(Problem(), fit);
    if (std::isfinite(variance)) last_log_radius_var_ = variance;
    else if (!same_shape) last_log_radius_var_ = options_.radius_prior_log_sigma * options_.radius_prior_log_sigma;
  };
  if (!estimate_.ok) {
    estimate_.problem = !plausible ? "fit left the plausible domain" : "residual above max_rms_sigma";
    ++counters_.fallbacks;
    // Amortized selection keeps a plausible best guess to refine while it explores.
    const bool keep = options_.selection == ModelSelection::kAmortized && plausible;
    if (keep) keep_radius_variance(), last_ = fit.model, last_prediction_ = fit.prediction;
    have_last_ = keep;
    have_last_chi2_ = false;
  } else {
    keep_radius_variance();
    last_ = fit.model;
    last_prediction_ = fit.prediction;
    have_last_ = true;
    last_chi2_per_dof_ = fit.chi2 / dof;
    have_last_chi2_ = true;
    if (fit.model.pair) ++counters_.two_contacts;
  }
}

}  // namespace sedbridge::contact
