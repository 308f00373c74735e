#include "fem/rotation_extraction.h"

#include <Eigen/SVD>
#include <cmath>

namespace sedbridge::fem {

namespace {

// Rotation update below which the iteration has converged [rad]: 1e-12 is round-off for a
// unit quaternion in double precision.
constexpr double kConvergedAngle_rad = 1e-12;
// Keeps the update finite when R and F are orthogonal (alignment 0) [-].
constexpr double kAlignmentFloor = 1e-9;

}  // namespace

Eigen::Matrix3d ExtractRotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q,
                                int max_iterations) {
  // Each iteration rotates R toward F by the torque-like vector sum_i r_i x f_i, scaled by
  // 1 / |sum_i r_i . f_i| (Mueller et al., "A robust method to extract the rotational part
  // of deformations", MIG 2016). The result is a rotation by construction.
  Eigen::Matrix3d R = q.toRotationMatrix();
  for (int it = 0; it < max_iterations; ++it) {
    const Eigen::Vector3d torque =
        R.col(0).cross(F.col(0)) + R.col(1).cross(F.col(1)) + R.col(2).cross(F.col(2));
    const double alignment =
        std::abs(R.col(0).dot(F.col(0)) + R.col(1).dot(F.col(1)) + R.col(2).dot(F.col(2)));
    const Eigen::Vector3d omega = torque / (alignment + kAlignmentFloor);
    const double angle = omega.norm();
    if (!(angle > kConvergedAngle_rad)) break;  // also stops on NaN input
    q = Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega / angle)) * q;
    q.normalize();
    R = q.toRotationMatrix();
  }
  if (!R.allFinite()) {
    q = Eigen::Quaterniond::Identity();
    R.setIdentity();
  }
  return R;
}

Eigen::Matrix3d PolarRotationSvd(const Eigen::Matrix3d& F) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0) U.col(2) *= -1;  // smallest singular value
  return U * V.transpose();
}

}  // namespace sedbridge::fem
