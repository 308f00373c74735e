#include "bridge/display_fidelity.h"

namespace sedbridge::bridge {

DisplayFidelity CompareDeliveredSed(const Eigen::Matrix3Xd& pad_mm, const Eigen::VectorXd& delivered,
                                    const Eigen::VectorXd& asked) {
  DisplayFidelity f;
  if (asked.size() == 0 || delivered.size() != asked.size() || pad_mm.cols() != asked.size()) return f;
  Eigen::Index id = 0, ia = 0;
  const double md = delivered.maxCoeff(&id), ma = asked.maxCoeff(&ia);
  const double norm = asked.norm();
  f.peak_ratio = ma > 0 ? md / ma : 0;
  f.rel_l2 = norm > 0 ? (delivered - asked).norm() / norm : 0;
  f.peak_offset_mm = (pad_mm.col(id).head<2>() - pad_mm.col(ia).head<2>()).norm();
  return f;
}

}  // namespace sedbridge::bridge
