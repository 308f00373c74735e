#pragma once
// Hold averaging: while the contact holds still (each scan agrees with the running mean of
// the scans since it last moved, within noise), the fit reads that mean with the mean's
// noise. A hold determines what one scan cannot (a thin rod's radius: its chi^2 moves by < 1
// between R = 1 and 3 mm in one scan of the rig, by tens over a hold's ~40 scans). Any change
// beyond noise starts the mean anew from that scan, so a moving contact is fitted scan by scan.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "contact/reconstruction_options.h"

namespace sedbridge::contact {

class HoldFilter {
 public:
  /// Reads max_hold_scans, hold_change_sigma and hold_force_change_sigma.
  explicit HoldFilter(const ReconstructionOptions& options)
      : max_scans_(options.max_hold_scans),
        change_sigma_(options.hold_change_sigma),
        force_change_sigma_(options.hold_force_change_sigma) {}

  /// Folds the scan (readings [N], weights 1 / single-scan noise, 0 where unused) into the hold
  /// mean, or restarts it from the scan when it moved or its valid/saturated taxels changed;
  /// returns the scans the mean holds.
  int Average(const Eigen::VectorXd& readings_N, const std::vector<uint8_t>& valid,
              const std::vector<uint8_t>& saturated, const Eigen::VectorXd& weight, const Eigen::VectorXd& inv_sigma);
  /// The mean of the scans since the contact last moved [N].
  const Eigen::VectorXd& mean_N() const { return mean_N_; }
  /// Forgets the mean: the next scan starts it anew.
  void Reset() { scans_ = 0; }

 private:
  int max_scans_;
  double change_sigma_, force_change_sigma_;
  Eigen::VectorXd mean_N_;
  std::vector<uint8_t> valid_, saturated_;  // the pattern the mean's scans share
  int scans_ = 0;
};

}  // namespace sedbridge::contact
