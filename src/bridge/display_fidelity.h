#pragma once
// What the display delivers against what the bridge asked of it, at one scan: the SED the
// published commands add to the leader's preloaded pad (full contact FE,
// InverseDisplayRequests::Deliver) against the bridge's Merkel SED, in the measures of the
// fidelity benchmark (docs/bridge-fidelity.md#the-measure).

#include <Eigen/Core>

namespace sedbridge::bridge {

struct DisplayFidelity {
  double peak_ratio = 0;      ///< max delivered / max asked (0 when nothing is asked)
  double rel_l2 = 0;          ///< |delivered - asked| / |asked| over the Merkel layer
  double peak_offset_mm = 0;  ///< pad-frame x-y distance between the two maxima [mm]
};

/// `delivered` against `asked` (SED per Merkel vertex [Pa]) at vertices `pad_mm` (3 x n).
DisplayFidelity CompareDeliveredSed(const Eigen::Matrix3Xd& pad_mm, const Eigen::VectorXd& delivered,
                                    const Eigen::VectorXd& asked);

}  // namespace sedbridge::bridge
