#pragma once
// Rotation part of a deformation gradient for corotational FEM.
//
// Always returns a proper rotation (det = +1), also for inverted or degenerate F: that is
// what keeps corotational elements stable when a hard press inverts a tet (the same
// concern SOFA and Vega FEM address with their "invertible" polar decompositions).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sedbridge::fem {

/// Rotation extraction: maximises tr(R^T F) over rotations by Newton's method on the
/// rotation (quadratic convergence), falling back to Mueller et al.'s robust step where
/// Newton's is not safe. Warm-started from `q`, which is updated in place: 1-2 iterations
/// when F changes little between calls. Stops when the update is below 1e-12 rad, after a
/// Newton step shorter than `last_newton_step_rad` (the error left is of the order of its
/// square: the default leaves ~1e-12 rad), or after `max_iterations`. Returns R.
/// Rotation update below which the iteration has converged [rad]: round-off for a unit
/// quaternion in double precision.
inline constexpr double kRotationConvergedAngle_rad = 1e-12;
/// Newton's step needs H's leading minors above this fraction of tr(S) (to their power).
inline constexpr double kRotationNewtonMargin = 1e-3;

Eigen::Matrix3d ExtractRotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q, int max_iterations = 20,
                                double last_newton_step_rad = 1e-6);

/// ExtractRotation(F[k], q[k], 20, last_newton_step_rad) for k < count, the few warm
/// Newton steps most need taken four at a time in vector registers (fem/rotation_step4.h),
/// ExtractRotation itself where they are not enough. The same rotations to round-off.
/// Returns how many took ExtractRotation.
int ExtractRotations(int count, const Eigen::Matrix3d* F, Eigen::Quaterniond* q, Eigen::Matrix3d* R,
                     double last_newton_step_rad);

/// Reference: SVD-based polar rotation with the smallest singular direction flipped for
/// inverted F (det F < 0). Slower; used in tests and as a cross-check.
Eigen::Matrix3d PolarRotationSvd(const Eigen::Matrix3d& F);

}  // namespace sedbridge::fem
