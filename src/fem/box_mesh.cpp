#include "fem/box_mesh.h"

#include <Eigen/Dense>
#include "fem/tet_element.h"

namespace sedbridge::fem {

int BoxNodeIndex(const Eigen::Vector3i& c, int i, int j, int k) {
  return i + (c.x() + 1) * (j + (c.y() + 1) * k);
}

TetMesh MakeBoxMesh(const Eigen::Vector3d& size, const Eigen::Vector3i& c, const LinearElasticMaterial& material) {
  TetMesh mesh;
  const int n = (c.x() + 1) * (c.y() + 1) * (c.z() + 1);
  mesh.rest_positions_m.resize(3, n);
  for (int k = 0; k <= c.z(); ++k)
    for (int j = 0; j <= c.y(); ++j)
      for (int i = 0; i <= c.x(); ++i)
        mesh.rest_positions_m.col(BoxNodeIndex(c, i, j, k)) =
            Eigen::Vector3d(size.x() * i / c.x(), size.y() * j / c.y(), size.z() * k / c.z());
  // Kuhn subdivision: the 6 monotone paths from corner 000 to 111.
  static const int kPaths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < c.z(); ++k)
    for (int j = 0; j < c.y(); ++j)
      for (int i = 0; i < c.x(); ++i)
        for (const auto& path : kPaths) {
          Eigen::Vector3i p(i, j, k);
          Tet t;
          t[0] = BoxNodeIndex(c, p.x(), p.y(), p.z());
          for (int s = 0; s < 3; ++s) {
            p[path[s]] += 1;
            t[size_t(s) + 1] = BoxNodeIndex(c, p.x(), p.y(), p.z());
          }
          const auto& x = mesh.rest_positions_m;
          if (SignedVolume(x.col(t[0]), x.col(t[1]), x.col(t[2]), x.col(t[3])) < 0) std::swap(t[2], t[3]);
          mesh.tets.push_back(t);
        }
  mesh.tet_material.assign(mesh.tets.size(), 0);
  mesh.materials = {material};
  return mesh;
}

}  // namespace sedbridge::fem
