#pragma once
// ExtractRotation's warm-started Newton step (fem/rotation_extraction.cpp) for four
// matrices at once in vector registers (GCC vector extensions; AVX2 in an x86-64-v3 clone,
// two SSE halves otherwise). Internal to the FE kernels that batch it: the force of the
// corotational element and ExtractRotations. Vectors pass by reference only (by value the
// baseline clone would pass 32-byte vectors without AVX, an ABI change GCC warns about).

#include "fem/rotation_extraction.h"

namespace sedbridge::fem::rotation_step4 {

using Doubles4 = double __attribute__((vector_size(32)));
using Mask4 = long long __attribute__((vector_size(32)));

/// R = the rotation of unit quaternion (x, y, z, w): Eigen's Quaternion::toRotationMatrix.
inline __attribute__((always_inline)) void ToRotation(const Doubles4& x, const Doubles4& y, const Doubles4& z,
                                                      const Doubles4& w, Doubles4 (&R)[3][3]) {
  const Doubles4 tx = 2 * x, ty = 2 * y, tz = 2 * z;
  const Doubles4 twx = tx * w, twy = ty * w, twz = tz * w, txx = tx * x, txy = ty * x, txz = tz * x;
  const Doubles4 tyy = ty * y, tyz = tz * y, tzz = tz * z;
  R[0][0] = 1 - (tyy + tzz), R[0][1] = txy - twz, R[0][2] = txz + twy;
  R[1][0] = txy + twz, R[1][1] = 1 - (txx + tzz), R[1][2] = tyz - twx;
  R[2][0] = txz - twy, R[2][1] = tyz + twx, R[2][2] = 1 - (txx + tyy);
}

/// One Newton step of the rotation of F from the warm quaternion q (x y z w): where the
/// step is safe (H definite) and below last_step_rad (the error left is its square), done
/// is set and q, R are the step's; elsewhere q is unchanged and the caller runs
/// ExtractRotation. A step below kRotationConvergedAngle_rad leaves q as it was, as there.
inline __attribute__((always_inline)) void NewtonStep(const Doubles4 (&F)[3][3], Doubles4& qx, Doubles4& qy,
                                                      Doubles4& qz, Doubles4& qw, double last_step_rad,
                                                      Doubles4 (&R)[3][3], Mask4& done) {
  using V = Doubles4;
  const V zero = {0, 0, 0, 0}, one = {1, 1, 1, 1};
  ToRotation(qx, qy, qz, qw, R);
  V A[3][3];  // R^T F
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) A[i][j] = R[0][i] * F[0][j] + R[1][i] * F[1][j] + R[2][i] * F[2][j];
  const V gx = A[2][1] - A[1][2], gy = A[0][2] - A[2][0], gz = A[1][0] - A[0][1];
  const V trace = A[0][0] + A[1][1] + A[2][2];
  const V h00 = trace - A[0][0], h11 = trace - A[1][1], h22 = trace - A[2][2];
  const V h01 = -0.5 * (A[0][1] + A[1][0]), h02 = -0.5 * (A[0][2] + A[2][0]), h12 = -0.5 * (A[1][2] + A[2][1]);
  const V c00 = h11 * h22 - h12 * h12, c01 = h02 * h12 - h01 * h22, c02 = h01 * h12 - h02 * h11;
  const V c11 = h00 * h22 - h02 * h02, c12 = h01 * h02 - h00 * h12, c22 = h00 * h11 - h01 * h01;
  const V margin = kRotationNewtonMargin * (trace < zero ? -trace : trace);
  const V m3 = h00 * c00 + h01 * c01 + h02 * c02;
  const Mask4 definite = (h00 > margin) & (c22 > margin * margin) & (m3 > margin * margin * margin);
  const V inv_det = definite ? one / m3 : zero;
  const V wx = inv_det * (c00 * gx + c01 * gy + c02 * gz), wy = inv_det * (c01 * gx + c11 * gy + c12 * gz),
          wz = inv_det * (c02 * gx + c12 * gy + c22 * gz);
  const V angle2 = wx * wx + wy * wy + wz * wz;
  // q (x) (1, w / 2), normalized: the exponential of a step below 1e-4 rad to round-off.
  // |q'|^2 = 1 + |h|^2 (to q's own round-off): one Newton step of 1/sqrt from 1 leaves
  // 3/8 (|q'|^2 - 1)^2 < 1e-17 (and needs no sqrt).
  const V hx = 0.5 * wx, hy = 0.5 * wy, hz = 0.5 * wz;
  V nw = qw - (qx * hx + qy * hy + qz * hz);
  V nx = qw * hx + qx + (qy * hz - qz * hy);
  V ny = qw * hy + qy + (qz * hx - qx * hz);
  V nz = qw * hz + qz + (qx * hy - qy * hx);
  const V norm2 = nw * nw + nx * nx + ny * ny + nz * nz;
  const V inv_norm = 1.5 - 0.5 * norm2;
  const Mask4 update = angle2 > kRotationConvergedAngle_rad * kRotationConvergedAngle_rad;
  const V off_unit = norm2 - 1.0;
  // The small-angle exponential needs the step below 1e-4 rad too (a longer one is not done).
  const double bound = last_step_rad < 1e-4 ? last_step_rad : 1e-4;
  done = definite & (angle2 < bound * bound) & (off_unit < 1e-6) & (off_unit > -1e-6);
  const Mask4 take = done & update;
  qx = take ? nx * inv_norm : qx, qy = take ? ny * inv_norm : qy;
  qz = take ? nz * inv_norm : qz, qw = take ? nw * inv_norm : qw;
  ToRotation(qx, qy, qz, qw, R);
}

}  // namespace sedbridge::fem::rotation_step4
