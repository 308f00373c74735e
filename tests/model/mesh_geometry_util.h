#pragma once
// Geometry helpers for the model tests: volumes, point-triangle distance, boundary edges.

#include <Eigen/Core>
#include <algorithm>
#include <map>
#include <utility>
#include <vector>

#include "fem/tet_mesh.h"

namespace sedbridge::model::testing {

inline double TetVolume(const Eigen::Matrix3Xd& x, const fem::Tet& t) {
  return (x.col(t[1]) - x.col(t[0])).cross(x.col(t[2]) - x.col(t[0])).dot(x.col(t[3]) - x.col(t[0])) / 6.0;
}

/// Closest point on triangle (a, b, c) to p (Voronoi-region walk).
inline Eigen::Vector3d ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                              const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

/// Distance from p to the nearest of `triangles` (brute force; test meshes are small).
inline double DistanceToSurface(const Eigen::Vector3d& p, const Eigen::Matrix3Xd& x,
                                const std::vector<fem::Triangle>& triangles) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : triangles) {
    best = std::min(best, (p - ClosestPointOnTriangle(p, x.col(t[0]), x.col(t[1]), x.col(t[2]))).norm());
  }
  return best;
}

/// Edges used by exactly one triangle (the border of an open surface), and whether every
/// interior edge is used by exactly two triangles in opposite directions (consistent
/// orientation).
inline std::vector<std::pair<int, int>> BorderEdges(const std::vector<fem::Triangle>& triangles,
                                                    bool* consistently_oriented) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : triangles) {
    for (int i = 0; i < 3; ++i) ++directed[{t[i], t[(i + 1) % 3]}];
  }
  std::vector<std::pair<int, int>> border;
  bool ok = true;
  for (const auto& [e, n] : directed) {
    if (n != 1) ok = false;  // the same directed edge twice: flipped neighbour or non-manifold
    if (!directed.count({e.second, e.first})) border.push_back(e);
  }
  if (consistently_oriented) *consistently_oriented = ok;
  return border;
}

}  // namespace sedbridge::model::testing
