#include "sensors/taxel_health.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sensors/calibration_press.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::sensors {
namespace {

// A taxel beyond this many sigma is loaded (drift's quiet scan; stuck high's "reads within noise").
constexpr double kQuietSigma = 4;
// A frozen taxel shows noise again when its readings stay bit-identical no longer than this
// many scans running; and most taxels doing so is a sensor that shows noise at all (a
// noise-free simulation repeats every unloaded reading: nothing there is frozen).
constexpr int kNoisyRunScans = 3;
// Dead: the ring's single point load must explain its readings within this fraction of
// their norm (a flat, a rod or two contacts are not one point: not judged).
constexpr double kRingFitRelative = 0.2;
// ... and every point load within this many noise variances (and this fraction of the
// readings' square norm) of the best fit's residual is as good an explanation.
constexpr double kFitNoiseSigma2 = 9;
constexpr double kFitSlack = 0.003;
// Stuck high under a press: at most this many taxels judged so in one scan (each costs a fit).
constexpr int kMaxExcessPerScan = 3;
// ... each the one taxel whose leaving out explains the others this many times better than
// leaving out any other does.
constexpr double kExcessDistinct = 10;

int Scans(double seconds, double rate_Hz, int at_least) {
  return std::max(at_least, static_cast<int>(std::lround(seconds * rate_Hz)));
}

double SmallestSpacing_mm(const std::vector<TaxelPosition>& taxels) {
  double d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < taxels.size(); ++i)
    for (size_t j = i + 1; j < taxels.size(); ++j)
      d = std::min(d, std::hypot(taxels[i].x_mm - taxels[j].x_mm, taxels[i].y_mm - taxels[j].y_mm));
  return std::isfinite(d) ? d : 0;
}

}  // namespace

const char* ToString(TaxelFault fault) {
  switch (fault) {
    case TaxelFault::kHealthy: return "healthy";
    case TaxelFault::kFrozen: return "frozen";
    case TaxelFault::kStuckHigh: return "stuck high";
    case TaxelFault::kDead: return "dead";
  }
  return "?";
}

TaxelHealth::TaxelHealth(const SensorProfile& profile)
    : t_(profile.taxel_health), n_(profile.taxel_count), axes_(profile.axes), scan_rate_Hz_(profile.scan_rate_Hz) {
  frozen_scans_ = t_.frozen_after_s > 0 ? Scans(t_.frozen_after_s, scan_rate_Hz_, 2) : 0;
  stuck_scans_ = Scans(t_.stuck_after_s, scan_rate_Hz_, 1);
  dead_scans_ = Scans(t_.dead_after_s, scan_rate_Hz_, 1);
  recover_scans_ = Scans(t_.recover_after_s, scan_rate_Hz_, 1);
  area_m2_ = profile.taxel_area_mm2() * 1e-6;
  state_.resize(size_t(n_));
  z_.assign(size_t(n_), 0.0);
  suspect_.assign(size_t(n_), 0);
  dead_suspect_.assign(size_t(n_), 0);
  sigma_N_.resize(size_t(n_));
  sigma_shear_N_.assign(size_t(n_), 0.0);
  for (int k = 0; k < n_; ++k) {
    sigma_N_[size_t(k)] = t_.noise_counts * NewtonsPerCount(profile, k, profile.NormalAxis());
    if (axes_ == 3)
      sigma_shear_N_[size_t(k)] =
          t_.noise_counts * 0.5 * (NewtonsPerCount(profile, k, 0) + NewtonsPerCount(profile, k, 1));
  }
  // The nearest ring: centres within 1.5 spacings (a grid's 8 neighbours).
  const double ring_mm = 1.5 * SmallestSpacing_mm(profile.taxels);
  ring_.resize(size_t(n_));
  for (int k = 0; k < n_; ++k)
    for (int j = 0; j < n_; ++j) {
      const auto& a = profile.taxels[size_t(k)];
      const auto& b = profile.taxels[size_t(j)];
      if (j != k && std::hypot(a.x_mm - b.x_mm, a.y_mm - b.y_mm) <= ring_mm) ring_[size_t(k)].push_back(j);
    }
  spread_.assign(size_t(n_), 0.0);
  if (t_.enabled && profile.has_forward_model && n_ >= 2) BuildModelBounds(profile);
}

void TaxelHealth::BuildModelBounds(const SensorProfile& profile) {
  const TactileForwardModel model(profile.taxels, profile.taxel_width_mm, profile.taxel_height_mm,
                                  profile.forward_model);
  // Point loads over the taxels' bounding box and half a spacing around it, a quarter
  // spacing apart: where a contact that reaches the taxels can press.
  const double d = SmallestSpacing_mm(profile.taxels);
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const TaxelPosition& p : profile.taxels) {
    x0 = std::min(x0, p.x_mm), x1 = std::max(x1, p.x_mm);
    y0 = std::min(y0, p.y_mm), y1 = std::max(y1, p.y_mm);
  }
  const double margin = 0.5 * d, step = std::max(0.25 * d, model.cell_size_mm());
  const int stride = std::max(1, static_cast<int>(std::lround(step / model.cell_size_mm())));
  std::vector<Eigen::VectorXd> rows, shear_rows;
  Eigen::VectorXd r;
  // On the grid through taxel 0's centre (a model grid node): symmetric loads are probed.
  const Eigen::Vector2d origin = model.CellCentre_mm(0);
  const int col0 = static_cast<int>(std::lround((profile.taxels[0].x_mm - origin.x()) / model.cell_size_mm()));
  const int row0 = static_cast<int>(std::lround((profile.taxels[0].y_mm - origin.y()) / model.cell_size_mm()));
  for (int i = ((row0 % stride) + stride) % stride; i < model.grid_n(); i += stride)
    for (int j = ((col0 % stride) + stride) % stride; j < model.grid_n(); j += stride) {
      const int cell = i * model.grid_n() + j;
      const Eigen::Vector2d c = model.CellCentre_mm(cell);
      if (c.x() < x0 - margin || c.x() > x1 + margin || c.y() < y0 - margin || c.y() > y1 + margin) continue;
      model.Respond({SurfaceLoad{cell, 1.0, 0, 0}}, &r);
      Eigen::VectorXd z(n_), s(n_);
      for (int k = 0; k < n_; ++k) z[k] = std::max(0.0, r[3 * k + 2]), s[k] = std::hypot(r[3 * k], r[3 * k + 1]);
      rows.push_back(z);
      shear_rows.push_back(s);
    }
  responses_.resize(Eigen::Index(rows.size()), n_);
  shear_responses_.resize(Eigen::Index(rows.size()), n_);
  for (size_t p = 0; p < rows.size(); ++p) {
    responses_.row(Eigen::Index(p)) = rows[p].transpose();
    shear_responses_.row(Eigen::Index(p)) = shear_rows[p].transpose();
  }
  UpdateBounds();
}

void TaxelHealth::UpdateBounds() {
  bounds_dirty_ = false;
  if (!ModelBased()) return;
  for (int k = 0; k < n_; ++k) {
    double var = 0;
    for (int j = 0; j < n_; ++j)
      if (j != k && !masked(j)) var += sigma_N_[size_t(j)] * sigma_N_[size_t(j)];
    const double sigma_others = std::sqrt(var), sigma_shear = sigma_shear_N_[size_t(k)];
    double spread = std::numeric_limits<double>::infinity();
    for (Eigen::Index p = 0; p < responses_.rows(); ++p) {
      const double own = responses_(p, k);
      if (!(own > 0)) continue;
      double others = 0, top = 0;
      for (int j = 0; j < n_; ++j)
        if (j != k && !masked(j)) others += responses_(p, j), top = std::max(top, responses_(p, j));
      double evidence = sigma_others > 0 ? (others - top) / sigma_others : 0;
      if (sigma_shear > 0) evidence += shear_responses_(p, k) / sigma_shear;
      spread = std::min(spread, evidence / own);
    }
    spread_[size_t(k)] = std::isfinite(spread) ? spread : 0;
  }
}

int TaxelHealth::masked_count() const {
  int m = 0;
  for (int k = 0; k < n_; ++k) m += masked(k);
  return m;
}

const Scan& TaxelHealth::Apply(const Scan& scan) {
  if (!t_.enabled || scan.num_taxels != n_ || static_cast<int>(scan.force_N.size()) != n_ ||
      static_cast<int>(scan.valid.size()) != n_)
    return scan;
  ++counters_.scans;
  for (int k = 0; k < n_; ++k) z_[size_t(k)] = scan.force_N[size_t(k)] - state_[size_t(k)].offset_N;
  TrackFrozen(scan);
  Judge(scan);
  TrackDrift(scan);
  if (bounds_dirty_) UpdateBounds();
  return Output(scan);
}

void TaxelHealth::TrackFrozen(const Scan& scan) {
  const bool have_last = last_raw_.size() == scan.raw_counts.size();
  for (int k = 0; k < n_ && have_last; ++k) {
    if (!scan.valid[size_t(k)]) continue;  // a missing frame carries its old reading
    bool same = true;
    for (int a = 0; a < axes_; ++a) same = same && scan.raw_counts[size_t(k * axes_ + a)] == last_raw_[size_t(k * axes_ + a)];
    int& run = state_[size_t(k)].unchanged_run;
    run = same ? run + 1 : 0;
  }
  last_raw_ = scan.raw_counts;
}

bool TaxelHealth::Stuck(int k, const Scan& scan) const {
  const double z = z_[size_t(k)], m = t_.isolated_margin_sigma;
  if (!(z > m * sigma_N_[size_t(k)])) return false;
  double others = 0, top = 0, var = 0;
  for (int j = 0; j < n_; ++j) {
    if (j == k || masked(j) || !scan.valid[size_t(j)]) continue;
    others += z_[size_t(j)], top = std::max(top, z_[size_t(j)]), var += sigma_N_[size_t(j)] * sigma_N_[size_t(j)];
  }
  double evidence = var > 0 ? (others - top) / std::sqrt(var) : 0;
  if (sigma_shear_N_[size_t(k)] > 0 && !scan.shear_x_Pa.empty())
    evidence += std::hypot(scan.shear_x_Pa[size_t(k)], scan.shear_y_Pa[size_t(k)]) * area_m2_ / sigma_shear_N_[size_t(k)];
  return evidence + m < t_.isolated_fraction * spread_[size_t(k)] * z;
}

void TaxelHealth::Judge(const Scan& scan) {
  int noisy = 0;
  for (const TaxelState& s : state_) noisy += s.unchanged_run < kNoisyRunScans;
  const bool sensor_noisy = 2 * noisy >= n_;
  // Stuck-high suspects first: they are no evidence of a load for the dead test's fit.
  for (int k = 0; k < n_; ++k) {
    suspect_[size_t(k)] = ModelBased() && scan.valid[size_t(k)] && Stuck(k, scan);
    dead_suspect_[size_t(k)] = 0;
  }
  // The dead test needs a loaded ring: on a quiet scan there is nothing to fit.
  const double sigma_min = *std::min_element(sigma_N_.begin(), sigma_N_.end());
  bool loaded = false;
  for (int k = 0; k < n_; ++k) loaded |= z_[size_t(k)] > t_.dead_margin_sigma * sigma_min;
  const bool fit = ModelBased() && loaded;
  outlier_ = -1;
  if (fit) {
    FitPointLoads(scan);
    // A taxel stuck high under a press is no evidence either: its neighbours would read
    // below a fit bent towards it and be judged dead.
    MarkExcess(scan);
  }
  for (int k = 0; k < n_; ++k) {
    if (!scan.valid[size_t(k)]) continue;
    TaxelState& s = state_[size_t(k)];
    const double z = z_[size_t(k)], sigma = sigma_N_[size_t(k)];
    const bool stuck = suspect_[size_t(k)];
    bool dead = false, dead_checkable = false;
    if (fit) {
      const double predicted = RingPrediction_N(k, scan);
      dead_checkable = predicted > t_.dead_margin_sigma * sigma;
      dead = dead_checkable && z < t_.dead_fraction * predicted;
    }
    const bool frozen = frozen_scans_ > 0 && sensor_noisy && s.unchanged_run >= frozen_scans_;
    if (!masked(k)) {
      // Left out at once only if it is the one whose leaving out explains the others best
      // (a healthy taxel beside a dead one may read below a fit bent by it, in some scans).
      dead_suspect_[size_t(k)] = dead && k == outlier_;
      s.stuck_run = stuck ? s.stuck_run + 1 : 0;
      s.dead_run = dead ? s.dead_run + 1 : 0;
      if (frozen) Mask(k, TaxelFault::kFrozen);
      else if (stuck && s.stuck_run >= stuck_scans_) Mask(k, TaxelFault::kStuckHigh);
      else if (dead && s.dead_run >= dead_scans_) Mask(k, TaxelFault::kDead);
      continue;
    }
    // Masked: back when it behaves, by the rule of what masked it, for recover_after_s.
    bool behaves = false, judged = true;
    switch (s.fault) {
      case TaxelFault::kFrozen: behaves = s.unchanged_run < kNoisyRunScans; break;
      case TaxelFault::kStuckHigh: behaves = !stuck && std::abs(z) < kQuietSigma * sigma; break;
      case TaxelFault::kDead: behaves = !dead, judged = dead_checkable; break;
      case TaxelFault::kHealthy: break;
    }
    if (!judged) continue;  // no load on its ring: a dead taxel cannot show it lives
    s.good_run = behaves && !frozen ? s.good_run + 1 : 0;
    if (s.good_run >= recover_scans_) {
      s = TaxelState{TaxelFault::kHealthy, s.unchanged_run, 0, 0, 0, s.baseline_N, s.offset_N};
      ++counters_.recovered;
      bounds_dirty_ = true;
    }
  }
}

void TaxelHealth::FitPointLoads(const Scan& scan) {
  // One least-squares point load over every usable taxel, per probe; a taxel's leave-one-out
  // fit takes its own term back out (RingPrediction_N).
  const Eigen::Index probes = responses_.rows();
  fit_num_.setZero(probes);
  fit_res_.resize(probes);
  fit_pred_.resize(probes);
  fit_den_.setZero(probes);
  fit_zz_ = fit_var_ = 0;
  for (int j = 0; j < n_; ++j) {
    if (!Usable(j, scan)) continue;
    const double z = z_[size_t(j)];
    fit_num_ += z * responses_.col(j);
    fit_den_ += responses_.col(j).cwiseAbs2();
    fit_zz_ += z * z, fit_var_ += sigma_N_[size_t(j)] * sigma_N_[size_t(j)];
  }
}

bool TaxelHealth::MarkExcess(const Scan& scan) {
  // The taxel whose leaving out explains the rest best is the one that lies, if any: a
  // healthy taxel beside a dead one reads more than a fit bent by the dead one implies,
  // but leaving the dead one out explains the rest better. If it reads too much, it is a
  // suspect, and the fit is redone without it (the next worst, up to kMaxExcessPerScan).
  bool any = false;
  for (int round = 0; round < kMaxExcessPerScan; ++round) {
    int& outlier = outlier_;
    outlier = -1;
    double least_res = std::numeric_limits<double>::infinity(), next_res = least_res;
    for (int k = 0; k < n_; ++k) {
      if (!Usable(k, scan)) continue;
      const double res = LeaveOutResidual(k);
      if (res < least_res) next_res = least_res, least_res = res, outlier = k;
      else next_res = std::min(next_res, res);
    }
    if (outlier < 0) break;
    const double zk = z_[size_t(outlier)], sk = sigma_N_[size_t(outlier)];
    // It alone lies (leaving out any other explains the rest kExcessDistinct times worse),
    // and by more than the others read together: no contact on the pad does that (a rod or
    // a flat the point loads explain poorly is not judged).
    if (!(zk > t_.dead_margin_sigma * sk) || !(kExcessDistinct * least_res < next_res)) break;
    double others = 0;
    for (int j = 0; j < n_; ++j) others += j != outlier && Usable(j, scan) ? z_[size_t(j)] : 0.0;
    if (!OthersLoaded(outlier, scan)) break;
    const double most = Implied_N(outlier, scan, true);
    if (!(most >= 0) || !(t_.dead_fraction * zk > most) || !(zk - most > others)) break;
    suspect_[size_t(outlier)] = 1;
    outlier = -1;
    any = true;
    FitPointLoads(scan);
  }
  return any;
}

bool TaxelHealth::OthersLoaded(int k, const Scan& scan) const {
  double others = 0, top = 0, var = 0;
  for (int j = 0; j < n_; ++j) {
    if (j == k || !Usable(j, scan)) continue;
    others += z_[size_t(j)], top = std::max(top, z_[size_t(j)]), var += sigma_N_[size_t(j)] * sigma_N_[size_t(j)];
  }
  return var > 0 && others - top > t_.dead_margin_sigma * std::sqrt(var);
}

double TaxelHealth::LeaveOutResidual(int k) const {
  const double zk = z_[size_t(k)];
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index p = 0; p < responses_.rows(); ++p) {
    const double r = responses_(p, k);
    const double num = fit_num_[p] - zk * r, den = fit_den_[p] - r * r;
    if (den > 0 && num > 0) best = std::min(best, fit_zz_ - zk * zk - num * num / den);
  }
  return best;
}

double TaxelHealth::RingPrediction_N(int k, const Scan& scan) const {
  // Only a taxel below its ring's largest reading, that reading above noise, can be dead
  // (most scans: nothing to fit).
  double ring_max = 0;
  for (int j : ring_[size_t(k)])
    if (Usable(j, scan)) ring_max = std::max(ring_max, z_[size_t(j)]);
  const double zk = z_[size_t(k)], sk = sigma_N_[size_t(k)];
  if (!(ring_max > t_.dead_margin_sigma * sk) || !(zk < ring_max)) return -1;
  return Implied_N(k, scan, false);
}

double TaxelHealth::Implied_N(int k, const Scan& scan, bool most) const {
  const double zk = z_[size_t(k)], sk = sigma_N_[size_t(k)];
  const bool in_fit = Usable(k, scan);
  const double zz = fit_zz_ - (in_fit ? zk * zk : 0), var = fit_var_ - (in_fit ? sk * sk : 0);
  // Every point load that explains the others about as well as the best one does is a
  // possible contact: the least of their predictions is what the fit says for certain.
  double best_res = std::numeric_limits<double>::infinity();
  for (Eigen::Index p = 0; p < responses_.rows(); ++p) {
    const double r = responses_(p, k);
    const double num = fit_num_[p] - (in_fit ? zk * r : 0), den = fit_den_[p] - (in_fit ? r * r : 0);
    fit_res_[p] = std::numeric_limits<double>::infinity();
    if (!(den > 0) || !(num > 0)) continue;
    fit_res_[p] = zz - num * num / den;  // least squares of the others by a * R(p, .), a = num / den
    fit_pred_[p] = num / den * r;
    best_res = std::min(best_res, fit_res_[p]);
  }
  if (!(best_res <= kRingFitRelative * kRingFitRelative * zz + kFitNoiseSigma2 * var)) return -1;
  const double acceptable = best_res + kFitNoiseSigma2 * var + kFitSlack * zz;
  double least = std::numeric_limits<double>::infinity(), greatest = -1;
  for (Eigen::Index p = 0; p < responses_.rows(); ++p)
    if (fit_res_[p] <= acceptable) least = std::min(least, fit_pred_[p]), greatest = std::max(greatest, fit_pred_[p]);
  if (most) return greatest;
  return std::isfinite(least) ? least : -1;
}

void TaxelHealth::Mask(int k, TaxelFault fault) {
  TaxelState& s = state_[size_t(k)];
  s.fault = fault;
  s.stuck_run = s.dead_run = s.good_run = 0;
  s.baseline_N = 0;
  ++(fault == TaxelFault::kFrozen ? counters_.masked_frozen
     : fault == TaxelFault::kStuckHigh ? counters_.masked_stuck
                                       : counters_.masked_dead);
  bounds_dirty_ = true;
}

void TaxelHealth::TrackDrift(const Scan& scan) {
  if (!(t_.drift_tau_s > 0)) return;
  // Quiet: no usable taxel loaded, or one only, by less than a stuck taxel's load.
  int loaded = 0;
  bool one_too_high = false;
  for (int k = 0; k < n_; ++k) {
    if (masked(k) || suspect_[size_t(k)] || !scan.valid[size_t(k)]) continue;
    const double a = std::abs(z_[size_t(k)]);
    if (a > kQuietSigma * sigma_N_[size_t(k)]) ++loaded, one_too_high |= a > t_.drift_max_sigma * sigma_N_[size_t(k)];
  }
  if (loaded > 1 || one_too_high) return;
  const double alpha = std::min(1.0, 1.0 / (t_.drift_tau_s * scan_rate_Hz_));
  for (int k = 0; k < n_; ++k) {
    if (masked(k) || suspect_[size_t(k)] || !scan.valid[size_t(k)]) continue;
    TaxelState& s = state_[size_t(k)];
    s.baseline_N += alpha * (z_[size_t(k)] - s.baseline_N);
    if (std::abs(s.baseline_N) > t_.drift_retare_sigma * sigma_N_[size_t(k)]) {
      s.offset_N += s.baseline_N;
      z_[size_t(k)] -= s.baseline_N;
      s.baseline_N = 0;
      ++counters_.retares;
    }
  }
}

const Scan& TaxelHealth::Output(const Scan& scan) {
  left_out_ = 0;
  bool retared = false;
  for (int k = 0; k < n_; ++k) {
    left_out_ += LeftOut(k);
    retared |= state_[size_t(k)].offset_N != 0;
  }
  counters_.masked_taxel_scans += left_out_;
  for (int k = 0; k < n_; ++k) counters_.suspect_taxel_scans += !masked(k) && LeftOut(k);
  if (left_out_ == 0 && !retared) return scan;
  out_ = scan;
  for (int k = 0; k < n_; ++k) {
    const double offset = state_[size_t(k)].offset_N;
    if (offset != 0) {
      out_.force_N[size_t(k)] -= offset;
      out_.pressure_Pa[size_t(k)] -= offset / area_m2_;
    }
    if (LeftOut(k)) {
      out_.valid[size_t(k)] = 0;
      out_.flags[size_t(k)] = uint8_t((out_.flags[size_t(k)] & ~kTaxelSaturated) | kTaxelMasked);
    }
  }
  return out_;
}

std::string TaxelHealth::Summary() const {
  std::string now;
  for (int k = 0; k < n_; ++k)
    if (masked(k)) now += (now.empty() ? "" : ", ") + std::to_string(k) + " " + ToString(fault(k));
  const TaxelHealthCounters& c = counters_;
  return "taxel health: " + std::to_string(masked_count()) + " masked now" + (now.empty() ? "" : " (" + now + ")") +
         "; " + std::to_string(c.masked_taxel_scans) + " taxel-scans left out (" + std::to_string(c.suspect_taxel_scans) +
         " suspects before masking); masked " + std::to_string(c.masked_frozen) + " frozen, " +
         std::to_string(c.masked_stuck) + " stuck high, " + std::to_string(c.masked_dead) + " dead; " +
         std::to_string(c.recovered) + " recovered; " + std::to_string(c.retares) + " drift re-tares";
}

}  // namespace sedbridge::sensors
