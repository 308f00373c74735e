#include "fem/mesh_topology.h"

#include <Eigen/Dense>
#include <algorithm>
#include <map>

namespace sedbridge::fem {

std::vector<Triangle> BoundaryFaces(const std::vector<Tet>& tets, const Eigen::Matrix3Xd& x) {
  // Faces of a positively oriented tet (a,b,c,d) with outward normals.
  static const int kFaces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  std::map<std::array<int, 3>, std::pair<Triangle, int>> count;
  for (const Tet& t : tets) {
    for (const auto& f : kFaces) {
      Triangle tri{t[size_t(f[0])], t[size_t(f[1])], t[size_t(f[2])]};
      std::array<int, 3> key = tri;
      std::sort(key.begin(), key.end());
      auto [it, inserted] = count.try_emplace(key, tri, 0);
      it->second.second++;
    }
  }
  std::vector<Triangle> out;
  for (const auto& [key, value] : count)
    if (value.second == 1) out.push_back(value.first);
  (void)x;
  return out;
}

std::vector<Eigen::Vector3d> VertexNormals(const std::vector<Triangle>& faces,
                                           const Eigen::Matrix3Xd& x, const std::vector<int>& nodes) {
  std::vector<Eigen::Vector3d> acc(size_t(x.cols()), Eigen::Vector3d::Zero());
  for (const Triangle& f : faces) {
    const Eigen::Vector3d n = (x.col(f[1]) - x.col(f[0])).cross(x.col(f[2]) - x.col(f[0]));
    for (int v : f) acc[size_t(v)] += n;  // |n| = 2 area: area weighting
  }
  std::vector<Eigen::Vector3d> out;
  out.reserve(nodes.size());
  for (int v : nodes) {
    const double len = acc[size_t(v)].norm();
    out.push_back(len > 0 ? Eigen::Vector3d(acc[size_t(v)] / len) : Eigen::Vector3d::Zero());
  }
  return out;
}

Eigen::VectorXd VertexAreas(const std::vector<Triangle>& faces, const Eigen::Matrix3Xd& x) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(x.cols());
  for (const Triangle& f : faces) {
    const double area = 0.5 * (x.col(f[1]) - x.col(f[0])).cross(x.col(f[2]) - x.col(f[0])).norm();
    for (int v : f) a[v] += area / 3.0;
  }
  return a;
}

}  // namespace sedbridge::fem
