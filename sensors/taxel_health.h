#pragma once
// Taxel health over time: which taxels of a sensor lie, judged scan by scan against the
// sensor's noise and its forward model (sensors/tactile_forward_model.h), with hysteresis.
//
//   frozen      all raw readings bit-identical for frozen_after_s while most taxels show
//               noise (a live taxel always shows the sensor's noise);
//   stuck high  a load no contact could produce: the taxel reads more than
//               isolated_margin_sigma while the evidence a load on it leaves elsewhere is
//               missing. A load anywhere near the taxel reaches the other taxels through the
//               elastomer or, off its centre, its own shear channels (forward model: for
//               every point load p, E(p) = (sum of the others' normal readings less the
//               largest, so that two adjacent stuck taxels are not each other's alibi) /
//               their noise + |own shear| / its noise, per unit own normal reading; its
//               least over the pad is the taxel's least spread). Suspect when the observed
//               E is below isolated_fraction x least spread x reading, by
//               isolated_margin_sigma. Or, under a press (the others less the largest
//               read above dead_margin_sigma of their noise), the mirror of dead below: the
//               taxel whose leaving out lets one point load explain the others best reads
//               more than the most such a load predicts for it, over dead_fraction (and
//               above dead_margin_sigma), by more than the others read together, and
//               leaving out any other taxel explains them ten times worse (a rod or flat
//               the point loads explain poorly is not judged); the test is redone without
//               it, up to 3 a scan.
//               Suspect in one scan: left out of that scan at once (and out of the dead
//               test's fit, whose others would read below a fit bent towards it); for
//               stuck_after_s running: masked;
//   dead        the taxel reads less than dead_fraction of what its loaded nearest ring
//               says: the single point load that explains the ring's normal readings best
//               (least squares over the model's point loads; only when it explains them
//               within a fifth of their norm, so a flat or two contacts are not judged)
//               predicts this taxel's reading, above dead_margin_sigma; left out of its
//               scan at once when it is also the taxel whose leaving out explains the
//               others best (beside a dead taxel a healthy one may read below a fit bent by
//               it, in some scans); for dead_after_s running: masked;
//   drifting    while the sensor is quiet (no taxel but this one beyond 4 sigma, this one
//               within drift_max_sigma), the taxel's normal reading is averaged with time
//               constant drift_tau_s; once that baseline is more than drift_retare_sigma off
//               zero it is re-tared: the baseline is taken off every later normal reading.
// A masked taxel comes back when it behaves for recover_after_s running (stuck high: reads
// within noise, its neighbours quiet; dead: reads what its ring implies; frozen: shows noise).
// Stuck-high and dead need the profile's forward_model; without one only frozen and drift.
//
// Apply returns the scan to use: the input itself while nothing is masked or re-tared (the
// healthy path costs no copy), else a copy with masked taxels invalid (kTaxelMasked, not
// saturated) and re-tared normal readings corrected.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sensors/scan.h"
#include "sensors/sensor_profile.h"
#include "sensors/taxel_health_thresholds.h"

namespace sedbridge::sensors {

enum class TaxelFault : uint8_t { kHealthy, kFrozen, kStuckHigh, kDead };
const char* ToString(TaxelFault fault);

struct TaxelHealthCounters {
  int64_t scans = 0;
  int64_t masked_taxel_scans = 0;    ///< taxels left out, summed over scans (masked + suspect)
  int64_t suspect_taxel_scans = 0;   ///< of those, suspects (stuck high or dead) not yet masked
  int64_t masked_frozen = 0;         ///< times a taxel was masked, per fault
  int64_t masked_stuck = 0;
  int64_t masked_dead = 0;
  int64_t recovered = 0;             ///< times a masked taxel came back
  int64_t retares = 0;               ///< drift re-tares
};

class TaxelHealth {
 public:
  /// Thresholds from profile.taxel_health; the forward model (when the profile has one)
  /// gives each taxel's least spread and ring bound (a few hundred point loads: ~ms).
  explicit TaxelHealth(const SensorProfile& profile);

  /// Judges `scan` and returns the scan to use (see above); the returned copy lives until
  /// the next call.
  const Scan& Apply(const Scan& scan);

  /// Taxels judged: the profile's taxel count.
  int taxel_count() const { return n_; }
  TaxelFault fault(int taxel) const { return state_[size_t(taxel)].fault; }
  bool masked(int taxel) const { return state_[size_t(taxel)].fault != TaxelFault::kHealthy; }
  /// Taxels left out of the last scan (masked, or suspects: stuck high or dead).
  int left_out() const { return left_out_; }
  int masked_count() const;
  /// Normal offset taken off a taxel by drift re-tares [N].
  double retare_offset_N(int taxel) const { return state_[size_t(taxel)].offset_N; }
  const TaxelHealthCounters& counters() const { return counters_; }
  /// "taxel health: 2 masked now (5 stuck high, 6 dead); 31 taxel-scans left out, ..."
  std::string Summary() const;

  /// The forward model's least spread of taxel k's load (see above) [sigma per N of its own
  /// normal reading], with the taxels masked now left out (for tests).
  double least_spread(int taxel) const { return spread_[size_t(taxel)]; }

 private:
  struct TaxelState {
    TaxelFault fault = TaxelFault::kHealthy;
    int unchanged_run = 0;   // scans its raw readings stayed bit-identical
    int stuck_run = 0, dead_run = 0, good_run = 0;
    double baseline_N = 0;   // drift: quiet-scan average of the corrected normal reading
    double offset_N = 0;     // drift: re-tared offset
  };

  void BuildModelBounds(const SensorProfile& profile);
  /// spread_ from the point-load responses, masked taxels left out.
  void UpdateBounds();
  /// Stuck-high suspect in this scan (see above).
  bool Stuck(int k, const Scan& scan) const;
  /// Neither masked nor a stuck-high suspect, and valid in `scan`.
  bool Usable(int j, const Scan& scan) const {
    return !masked(j) && !suspect_[size_t(j)] && scan.valid[size_t(j)];
  }
  /// Left out of this scan: masked, or a suspect (stuck high or dead) not yet masked.
  bool LeftOut(int k) const { return masked(k) || suspect_[size_t(k)] || dead_suspect_[size_t(k)]; }
  /// The point-load least squares of this scan over every usable taxel, per probe.
  void FitPointLoads(const Scan& scan);
  /// Taxel k's normal reading [N] as the point load that best explains the other taxels
  /// predicts it (-1: not judged: its ring is unloaded, or one point does not explain them).
  double RingPrediction_N(int k, const Scan& scan) const;
  /// The least (most: the greatest) normal reading of taxel k [N] that the point loads
  /// explaining the other usable taxels about as well as the best one does predict (-1: one
  /// point does not explain them).
  double Implied_N(int k, const Scan& scan, bool most) const;
  /// Stuck high under a press (see above): the taxel whose leaving out explains the others
  /// best becomes a suspect when it reads more than the most they imply over dead_fraction,
  /// and the fit is redone without it (then the next); true if any.
  bool MarkExcess(const Scan& scan);
  /// The usable taxels but k, less the largest of them, read more than dead_margin_sigma of
  /// their summed noise: a press that tells what k should read.
  bool OthersLoaded(int k, const Scan& scan) const;
  /// The least square residual of the usable taxels but k (k usable) by one point load.
  double LeaveOutResidual(int k) const;
  void TrackFrozen(const Scan& scan);
  /// This scan's suspects from the corrected normal readings z_.
  void Judge(const Scan& scan);
  void Mask(int k, TaxelFault fault);
  void TrackDrift(const Scan& scan);
  const Scan& Output(const Scan& scan);
  bool ModelBased() const { return responses_.rows() > 0; }

  TaxelHealthThresholds t_;
  int n_ = 0, axes_ = 1;
  double scan_rate_Hz_ = 100;
  double area_m2_ = 1;                     // taxel area: force_N = pressure_Pa * area
  int frozen_scans_ = 0, stuck_scans_ = 0, dead_scans_ = 0, recover_scans_ = 0;
  std::vector<double> sigma_N_;            // per taxel, normal reading noise [N]
  std::vector<double> sigma_shear_N_;      // per taxel, shear reading noise [N] (3-axis)
  std::vector<std::vector<int>> ring_;     // per taxel, its nearest ring
  Eigen::MatrixXd responses_;              // point load p (row) -> taxel normal reading (col)
  Eigen::MatrixXd shear_responses_;        // point load p (row) -> |taxel shear reading| (col)
  std::vector<double> spread_;
  Eigen::VectorXd fit_num_, fit_den_;      // this scan's point-load least squares, per probe
  double fit_zz_ = 0, fit_var_ = 0;
  mutable Eigen::VectorXd fit_res_, fit_pred_;  // RingPrediction_N's per-probe scratch
  std::vector<TaxelState> state_;
  std::vector<int32_t> last_raw_;
  std::vector<double> z_;                  // this scan's normal readings, re-tare applied [N]
  std::vector<uint8_t> suspect_;           // this scan: stuck-high suspect
  std::vector<uint8_t> dead_suspect_;      // this scan: judged dead, not yet masked
  int outlier_ = -1;                       // this scan: the taxel whose leaving out explains the rest best
  int left_out_ = 0;
  bool bounds_dirty_ = false;
  Scan out_;
  TaxelHealthCounters counters_;
};

}  // namespace sedbridge::sensors
