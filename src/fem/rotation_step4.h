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

/// Four consecutive doubles into a vector, and back.
inline __attribute__((always_inline)) void Load4(Doubles4& r, const double* p) { __builtin_memcpy(&r, p, sizeof(r)); }
inline __attribute__((always_inline)) void Store4(double* p, const Doubles4& r) { __builtin_memcpy(p, &r, sizeof(r)); }

/// The quaternions of four consecutive elements as Eigen stores them (x y z w, four doubles
/// an element) into one vector per component, and back.
inline __attribute__((always_inline)) void LoadQuaternions(const double* q, Doubles4& qx, Doubles4& qy, Doubles4& qz,
                                                           Doubles4& qw) {
  qx = Doubles4{q[0], q[4], q[8], q[12]}, qy = Doubles4{q[1], q[5], q[9], q[13]};
  qz = Doubles4{q[2], q[6], q[10], q[14]}, qw = Doubles4{q[3], q[7], q[11], q[15]};
}
inline __attribute__((always_inline)) void StoreQuaternions(double* q, const Doubles4& qx, const Doubles4& qy,
                                                            const Doubles4& qz, const Doubles4& qw) {
  for (int l = 0; l < 4; ++l) q[4 * l] = qx[l], q[4 * l + 1] = qy[l], q[4 * l + 2] = qz[l], q[4 * l + 3] = qw[l];
}

/// Edge vectors of elements e..e+3 stored as structures of arrays with `count` entries (node
/// a's 3 * index at offset[a * count + e]) for nodal values x: d[k][c] = component k of node
/// c + 1 minus node 0 (Ds for positions).
inline __attribute__((always_inline)) void EdgeVectors(int e, int count, const int* offset, const double* x,
                                                       Doubles4 (&d)[3][3]) {
  const int* o0 = offset + e;
  for (int c = 0; c < 3; ++c) {
    const int* oc = offset + (c + 1) * count + e;
    for (int k = 0; k < 3; ++k)
      d[k][c] = Doubles4{x[oc[0] + k], x[oc[1] + k], x[oc[2] + k], x[oc[3] + k]} -
                Doubles4{x[o0[0] + k], x[o0[1] + k], x[o0[2] + k], x[o0[3] + k]};
  }
}

/// F = Ds Dm^-1 of elements e..e+3 (layout as EdgeVectors; Dm^-1 (i, j) at
/// rest_inverse[(3 i + j) * count + e]); W gets their Dm^-1 (the kernels read it again).
inline __attribute__((always_inline)) void DeformationGradients(int e, int count, const int* offset,
                                                                const double* rest_inverse, const double* x,
                                                                Doubles4 (&W)[3][3], Doubles4 (&F)[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Load4(W[i][j], rest_inverse + (3 * i + j) * count + e);
  Doubles4 d[3][3];
  EdgeVectors(e, count, offset, x, d);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) F[i][j] = d[i][0] * W[0][j] + d[i][1] * W[1][j] + d[i][2] * W[2][j];
}

/// Newton steps of the rotation of F from the warm quaternion q (x y z w), at most
/// max_steps, as ExtractRotation takes them: a lane steps while its step is safe (H
/// definite) and shorter than kMaxVectorStep_rad, by the exact exponential (a series in the
/// squared angle, no sin/cos) or, below 1e-4 rad, by (1, w/2) normalized; it is done (its
/// q, R the result) after a step below last_step_rad (the error left is its square) or
/// below kRotationConvergedAngle_rad (q then unchanged). Elsewhere done is clear and the
/// caller runs ExtractRotation, from q as the steps left it (the same iteration, resumed).
inline constexpr double kMaxVectorStep_rad = 0.05;
/// Steps a batch takes at most: a warm start a few degrees off needs two or three.
inline constexpr int kMaxRotationSteps = 3;
inline __attribute__((always_inline)) void NewtonSteps(const Doubles4 (&F)[3][3], Doubles4& qx, Doubles4& qy,
                                                       Doubles4& qz, Doubles4& qw, double last_step_rad,
                                                       int max_steps, Doubles4 (&R)[3][3], Mask4& done) {
  using V = Doubles4;
  const V zero = {0, 0, 0, 0}, one = {1, 1, 1, 1};
  done = Mask4{0, 0, 0, 0};
  Mask4 active = Mask4{-1, -1, -1, -1};
  ToRotation(qx, qy, qz, qw, R);
  for (int step = 0; step < max_steps; ++step) {
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
    // exp(w) = (cos(a/2), sin(a/2) w / a): with y = a^2 / 4 < 6.3e-4 the series to y^4 is
    // exact to round-off. Below 1e-4 rad ExtractRotation's (1, w/2) (the same to O(a^3)).
    const V y = 0.25 * angle2;
    const Mask4 small = angle2 < 1e-8;
    const V c = small ? one : 1 - y * (1.0 / 2 - y * (1.0 / 24 - y * (1.0 / 720 - y * (1.0 / 40320))));
    const V sh = small ? 0.5 * one : 0.5 * (1 - y * (1.0 / 6 - y * (1.0 / 120 - y * (1.0 / 5040 - y * (1.0 / 362880)))));
    const V hx = sh * wx, hy = sh * wy, hz = sh * wz;
    const V nw = c * qw - (qx * hx + qy * hy + qz * hz);
    const V nx = qw * hx + c * qx + (qy * hz - qz * hy);
    const V ny = qw * hy + c * qy + (qz * hx - qx * hz);
    const V nz = qw * hz + c * qz + (qx * hy - qy * hx);
    // |q'|^2 - 1 is O(a^4) below 1e-4 rad and round-off above: one Newton step of 1/sqrt
    // from 1 leaves 3/8 (|q'|^2 - 1)^2 < 1e-17 (and needs no sqrt).
    const V norm2 = nw * nw + nx * nx + ny * ny + nz * nz;
    const V inv_norm = 1.5 - 0.5 * norm2;
    const V off_unit = norm2 - 1.0;
    const Mask4 steps = active & definite & (angle2 < kMaxVectorStep_rad * kMaxVectorStep_rad) &
                        (off_unit < 1e-6) & (off_unit > -1e-6);
    const Mask4 take = steps & (angle2 > kRotationConvergedAngle_rad * kRotationConvergedAngle_rad);
    qx = take ? nx * inv_norm : qx, qy = take ? ny * inv_norm : qy;
    qz = take ? nz * inv_norm : qz, qw = take ? nw * inv_norm : qw;
    const Mask4 finished = steps & (angle2 < last_step_rad * last_step_rad);
    done |= finished;
    active = steps & ~finished;
    ToRotation(qx, qy, qz, qw, R);
    if (!(active[0] | active[1] | active[2] | active[3])) break;
  }
}

}  // namespace sedbridge::fem::rotation_step4
