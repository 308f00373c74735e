#include "fem/rotation_extraction.h"

#include <Eigen/SVD>
#include <cmath>
#include <vector>

#include "common/hot_clones.h"
#include "fem/rotation_step4.h"

namespace sedbridge::fem {

namespace {

// Keeps the update finite when R and F are orthogonal (alignment 0) [-].
constexpr double kAlignmentFloor = 1e-9;
// Newton's step is taken when H's leading minors exceed kRotationNewtonMargin times tr(S)
// (to their power) and the step is shorter than kMaxNewtonStep_rad; otherwise the robust step.
constexpr double kMaxNewtonStep_rad = 0.5;
// Below this step the quaternion of exp(w) is (1, w/2) to within round-off [rad].
constexpr double kSmallAngle_rad = 1e-4;

}  // namespace

Eigen::Matrix3d ExtractRotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q, int max_iterations,
                                double last_newton_step_rad) {
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
    Eigen::Vector3d omega;
    // H = tr(S) I - S (symmetric) by its six entries and its adjugate: H^-1 g = adj(H) g / det H.
    const double h00 = trace - A(0, 0), h11 = trace - A(1, 1), h22 = trace - A(2, 2);
    const double h01 = -0.5 * (A(0, 1) + A(1, 0)), h02 = -0.5 * (A(0, 2) + A(2, 0)), h12 = -0.5 * (A(1, 2) + A(2, 1));
    const double c00 = h11 * h22 - h12 * h12, c01 = h02 * h12 - h01 * h22, c02 = h01 * h12 - h02 * h11;
    const double c11 = h00 * h22 - h02 * h02, c12 = h01 * h02 - h00 * h12, c22 = h00 * h11 - h01 * h01;
    // Positive definite, by leading minors, with a margin against a nearly singular H.
    const double margin = kRotationNewtonMargin * std::abs(trace);
    const double m1 = h00, m2 = c22, m3 = h00 * c00 + h01 * c01 + h02 * c02;
    bool newton_step = false;
    if (m1 > margin && m2 > margin * margin && m3 > margin * margin * margin) {
      const double inv_det = 1.0 / m3;
      omega = inv_det * Eigen::Vector3d(c00 * g.x() + c01 * g.y() + c02 * g.z(), c01 * g.x() + c11 * g.y() + c12 * g.z(),
                                        c02 * g.x() + c12 * g.y() + c22 * g.z());
      newton_step = omega.squaredNorm() < kMaxNewtonStep_rad * kMaxNewtonStep_rad;
    }
    if (!newton_step) omega = g / (std::abs(trace) + kAlignmentFloor);
    const double angle = omega.norm();
    if (!(angle > kRotationConvergedAngle_rad)) break;  // also stops on NaN input
    if (angle < kSmallAngle_rad) {
      // exp of a small rotation to O(angle^3), below round-off in the converged result
      q = q * Eigen::Quaterniond(1.0, 0.5 * omega.x(), 0.5 * omega.y(), 0.5 * omega.z());
    } else {
      q = q * Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega / angle));
    }
    q.normalize();
    R = q.toRotationMatrix();
    // Newton's error after this step is of the order of its square: another iteration
    // would only confirm it.
    if (newton_step && angle < last_newton_step_rad) break;
  }
  if (!R.allFinite()) {
    q = Eigen::Quaterniond::Identity();
    R.setIdentity();
  }
  return R;
}

namespace {

// Four at a time from index `begin` while four are left; status[k] = 1 where ExtractRotation
// must answer (including the last count % 4).
SEDBRIDGE_HOT_CLONES
void RotationStepsBy4(int count, const double* F, double* q, double* R, double last_step_rad, double* status) {
  using rotation_step4::Doubles4;
  using rotation_step4::Mask4;
  const int vector_end = count / 4 * 4;
  for (int k = vector_end; k < count; ++k) status[k] = 1.0;
  for (int k = 0; k < vector_end; k += 4) {
    // Eigen's matrices are column-major: F(i, j) at [9 k + 3 j + i]; quaternions x y z w.
    Doubles4 f[3][3] = {}, r[3][3] = {};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double* p = F + 9 * k + 3 * j + i;
        f[i][j] = Doubles4{p[0], p[9], p[18], p[27]};
      }
    double* w = q + 4 * k;
    Doubles4 qx, qy, qz, qw;
    rotation_step4::LoadQuaternions(w, qx, qy, qz, qw);
    Mask4 done;
    rotation_step4::NewtonSteps(f, qx, qy, qz, qw, last_step_rad, rotation_step4::kMaxRotationSteps, r, done);
    rotation_step4::StoreQuaternions(w, qx, qy, qz, qw);
    for (int l = 0; l < 4; ++l) {
      status[k + l] = done[l] ? 0.0 : 1.0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) R[9 * (k + l) + 3 * j + i] = r[i][j][l];
    }
  }
}

}  // namespace

int ExtractRotations(int count, const Eigen::Matrix3d* F, Eigen::Quaterniond* q, Eigen::Matrix3d* R,
                     double last_newton_step_rad) {
  if (count <= 0) return 0;
  static_assert(sizeof(Eigen::Matrix3d) == 9 * sizeof(double) && sizeof(Eigen::Quaterniond) == 4 * sizeof(double),
                "matrices and quaternions are read nine and four doubles apart");
  thread_local std::vector<double> status;
  status.resize(size_t(count));
  RotationStepsBy4(count, F[0].data(), q[0].coeffs().data(), R[0].data(), last_newton_step_rad, status.data());
  int scalar = 0;
  for (int k = 0; k < count; ++k)
    if (status[size_t(k)] != 0) {
      R[k] = ExtractRotation(F[k], q[k], 20, last_newton_step_rad);
      ++scalar;
    }
  return scalar;
}

Eigen::Matrix3d PolarRotationSvd(const Eigen::Matrix3d& F) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0) U.col(2) *= -1;  // smallest singular value
  return U * V.transpose();
}

}  // namespace sedbridge::fem
