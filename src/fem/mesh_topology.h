#pragma once
// Boundary faces and vertex normals of a tet mesh.

#include <Eigen/Core>
#include <vector>

#include "fem/tet_mesh.h"

namespace sedbridge::fem {

/// Faces that belong to exactly one tet, oriented with outward normals.
std::vector<Triangle> BoundaryFaces(const std::vector<Tet>& tets, const Eigen::Matrix3Xd& positions);

/// Area-weighted unit normals at `nodes` from `faces` (zero vector where no face touches).
std::vector<Eigen::Vector3d> VertexNormals(const std::vector<Triangle>& faces,
                                           const Eigen::Matrix3Xd& positions,
                                           const std::vector<int>& nodes);

/// Area of each node's share (one third of each adjacent face) [m^2], indexed by node.
Eigen::VectorXd VertexAreas(const std::vector<Triangle>& faces, const Eigen::Matrix3Xd& positions);

}  // namespace sedbridge::fem
