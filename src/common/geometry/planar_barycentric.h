#pragma once
// Barycentric coordinates in a triangle seen from above: what a load placed on the skin by
// its position in the pad's plane (a suction hole's disc, a pressure cell) shares among the
// three nodes of the skin face under it.

#include <Eigen/Core>
#include <cmath>

namespace sedbridge::geometry {

/// Barycentric coordinates w (w0 + w1 + w2 = 1) of q in the triangle (a, b, c), all in one
/// plane's coordinates [any length unit]. False for a degenerate triangle (w untouched).
/// A point outside the triangle has a negative coordinate.
inline bool PlanarBarycentric(const Eigen::Vector2d& q, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                              const Eigen::Vector2d& c, Eigen::Vector3d& w) {
  const Eigen::Vector2d e1 = b - a, e2 = c - a, d = q - a;
  const double det = e1.x() * e2.y() - e1.y() * e2.x();
  if (!(std::abs(det) > 1e-30)) return false;
  w[1] = (d.x() * e2.y() - d.y() * e2.x()) / det;
  w[2] = (e1.x() * d.y() - e1.y() * d.x()) / det;
  w[0] = 1.0 - w[1] - w[2];
  return true;
}

}  // namespace sedbridge::geometry
