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
// Newton's step is taken when H's leading minors exceed this fraction of tr(S) (to their
// power) and the step is shorter than kMaxNewtonStep_rad; otherwise the robust step.
constexpr double kNewtonMargin = 1e-3;
constexpr double kMaxNewtonStep_rad = 0.5;
// Below this step the quaternion of exp(w) is (1, w/2) to within round-off [rad].
constexpr double kSmallAngle_rad = 1e-4;

}  // namespace

Eigen::Matrix3d ExtractRotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q,
                                int max_iterations) {
  // Maximises tr(R^T F) over R = R_q exp([w]). In the element frame A = R^T F, the
  // objective is tr(A) + g.w - w^T H w / 2 with g = axial(A - A^T) and H = tr(S) I - S,
  // S = sym(A). Newton's step w = H^-1 g converges quadratically (2-3 steps from a warm
  // start). Mueller et al.'s step, w = g / |tr A| ("A robust method to extract the
  // rotational part of deformations", MIG 2016), replaces H by tr(S) I: near S = I that is
  // 3/2 of H, so it only gains a factor 3 per step (about 20 steps to round-off); it stays
  // the fallback where H is not positive definite (far from the maximum, inverted F).
  // Every update is a unit quaternion, so R is a rotation whatever F is.
  Eigen::Matrix3d R = q.toRotationMatrix();
  for (int it = 0; it < max_iterations; ++it) {
    const Eigen::Matrix3d A = R.transpose() * F;
    const Eigen::Vector3d g(A(2, 1) - A(1, 2), A(0, 2) - A(2, 0), A(1, 0) - A(0, 1));
    const double trace = A.trace();
    Eigen::Vector3d omega = g / (std::abs(trace) + kAlignmentFloor);
    const Eigen::Matrix3d S = 0.5 * (A + A.transpose());
    Eigen::Matrix3d H = -S;
    H.diagonal().array() += trace;
    // Positive definite, by leading minors, with a margin against a nearly singular H.
    const double margin = kNewtonMargin * std::abs(trace);
    const double m1 = H(0, 0);
    const double m2 = H(0, 0) * H(1, 1) - H(0, 1) * H(1, 0);
    const double m3 = H.determinant();
    if (m1 > margin && m2 > margin * margin && m3 > margin * margin * margin) {
      const Eigen::Vector3d newton = H.inverse() * g;
      if (newton.norm() < kMaxNewtonStep_rad) omega = newton;
    }
    const double angle = omega.norm();
    if (!(angle > kConvergedAngle_rad)) break;  // also stops on NaN input
    if (angle < kSmallAngle_rad) {
      // exp of a small rotation to O(angle^3), below round-off in the converged result
      q = q * Eigen::Quaterniond(1.0, 0.5 * omega.x(), 0.5 * omega.y(), 0.5 * omega.z());
    } else {
      q = q * Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega / angle));
    }
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
