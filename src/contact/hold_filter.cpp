#include "contact/hold_filter.h"

#include <algorithm>
#include <cmath>

namespace sedbridge::contact {

int HoldFilter::Average(const Eigen::VectorXd& readings_N, const std::vector<uint8_t>& valid,
                        const std::vector<uint8_t>& saturated, const Eigen::VectorXd& weight,
                        const Eigen::VectorXd& inv_sigma) {
  bool stationary = max_scans_ > 1 && scans_ > 0 && valid == valid_ && saturated == saturated_ &&
                    mean_N_.size() == readings_N.size();
  if (stationary) {
    double chi2 = 0, sum_z = 0, var_sum_z = 0;
    int count = 0;
    for (Eigen::Index c = 0; c < readings_N.size(); ++c)
      if (weight[c] > 0) {
        const double d = (readings_N[c] - mean_N_[c]) * inv_sigma[c];
        chi2 += d * d;
        ++count;
        if (c % 3 == 2) {
          sum_z += readings_N[c] - mean_N_[c];
          var_sum_z += 1.0 / (inv_sigma[c] * inv_sigma[c]);
        }
      }
    // Pure noise: (scan - mean of N) has variance (1 + 1/N) sigma^2 per reading. The sum of
    // the normal readings is tested on its own: a press or release moves it coherently
    // (a ramp's step per scan is under a sigma per taxel but several sigma in the sum).
    const double expected = 1.0 + 1.0 / scans_;
    stationary = count > 0 && chi2 / count <= expected * (1.0 + change_sigma_ * std::sqrt(2.0 / count)) &&
                 sum_z * sum_z <= force_change_sigma_ * force_change_sigma_ * expected * var_sum_z;
  }
  if (!stationary) {
    mean_N_ = readings_N;
    valid_ = valid;
    saturated_ = saturated;
    scans_ = 1;
    return 1;
  }
  scans_ = std::min(scans_ + 1, max_scans_);
  mean_N_ += (readings_N - mean_N_) / scans_;
  return scans_;
}

}  // namespace sedbridge::contact
