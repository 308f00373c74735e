#include "view/sed_mesh.h"

#include <cmath>
#include <exception>
#include <map>
#include <tuple>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/fingertip_model.h"

namespace sedbridge::view {
namespace {

// Rest positions agree to float precision; 1 um cells key them.
using Cell = std::tuple<long, long, long>;
Cell CellOf(double x, double y, double z) {
  return {std::lround(x * 1e3), std::lround(y * 1e3), std::lround(z * 1e3)};
}

void AddSurface(const model::FingertipModel& m, const std::vector<fem::Triangle>& triangles,
                std::vector<double>* xyz, std::vector<int>* tris) {
  std::map<int, int> local;  // soft node -> surface vertex
  for (const fem::Triangle& t : triangles)
    for (int k = 0; k < 3; ++k) {
      auto [it, added] = local.emplace(t[k], int(local.size()));
      if (added) {
        const Eigen::Vector3d p = m.pad_frame.ToPad(m.soft.rest_positions_m.col(t[k])) * 1e3;
        xyz->insert(xyz->end(), {p.x(), p.y(), p.z()});
      }
      tris->push_back(it->second);
    }
}

}  // namespace

SedMesh LoadSedMesh(const std::string& model) {
  SedMesh mesh;
  mesh.model_id = model;
  try {
    const model::FingertipModel m = model::LoadFingertipModel(model);
    mesh.model_id = m.name;
    AddSurface(m, m.merkel_triangles, &mesh.merkel_xyz_mm, &mesh.merkel_triangles);
    AddSurface(m, m.skin_triangles, &mesh.skin_xyz_mm, &mesh.skin_triangles);
    mesh.skin_merkel = MapSkinToMerkel(mesh);
  } catch (const std::exception& e) {
    mesh = SedMesh{};
    mesh.model_id = model;
    mesh.error = e.what();
  }
  return mesh;
}

std::vector<int> MapSkinToMerkel(const SedMesh& mesh, double max_depth_mm, double max_off_axis_mm) {
  using V = Eigen::Vector3d;
  const std::size_t ns = mesh.skin_xyz_mm.size() / 3, nm = mesh.num_merkel_vertices();
  const auto skin = [&](std::size_t v) { return V(mesh.skin_xyz_mm[3 * v], mesh.skin_xyz_mm[3 * v + 1], mesh.skin_xyz_mm[3 * v + 2]); };
  const auto merkel = [&](std::size_t v) {
    return V(mesh.merkel_xyz_mm[3 * v], mesh.merkel_xyz_mm[3 * v + 1], mesh.merkel_xyz_mm[3 * v + 2]);
  };
  // Vertex normals: the triangles' cross products (area-weighted), summed. The skin's
  // triangles are oriented outward (model/fingertip_model.h).
  std::vector<V> normal(ns, V::Zero());
  for (std::size_t t = 0; t + 2 < mesh.skin_triangles.size(); t += 3) {
    const int a = mesh.skin_triangles[t], b = mesh.skin_triangles[t + 1], c = mesh.skin_triangles[t + 2];
    const V n = (skin(std::size_t(b)) - skin(std::size_t(a))).cross(skin(std::size_t(c)) - skin(std::size_t(a)));
    for (int k : {a, b, c}) normal[std::size_t(k)] += n;
  }
  std::vector<int> beneath(ns, -1);
  for (std::size_t v = 0; v < ns; ++v) {
    if (normal[v].norm() == 0) continue;
    const V n = normal[v].normalized(), p = skin(v);
    double best = max_off_axis_mm;
    for (std::size_t m = 0; m < nm; ++m) {
      const V d = merkel(m) - p;
      const double depth = -d.dot(n);  // below the skin, along the inward normal
      if (depth <= 0 || depth > max_depth_mm) continue;
      const double off_axis = (d + depth * n).norm();
      if (off_axis < best) best = off_axis, beneath[v] = int(m);
    }
  }
  return beneath;
}

const std::vector<int>& SedVertexMatch::Match(const SedMesh& mesh, const std::vector<float>& x_mm,
                                              const std::vector<float>& y_mm, const std::vector<float>& z_mm) {
  const std::size_t n = x_mm.size();
  const bool same = index_.size() == n && n > 0 && first_xyz_ == std::vector<float>{x_mm[0], y_mm[0], z_mm[0]};
  if (same) return index_;
  index_.assign(n, -1);
  matched_ = 0;
  if (y_mm.size() != n || z_mm.size() != n) return index_;
  std::map<Cell, int> at;
  for (std::size_t v = 0; v < mesh.num_merkel_vertices(); ++v)
    at.emplace(CellOf(mesh.merkel_xyz_mm[3 * v], mesh.merkel_xyz_mm[3 * v + 1], mesh.merkel_xyz_mm[3 * v + 2]),
               int(v));
  for (std::size_t k = 0; k < n; ++k) {
    const Cell c = CellOf(x_mm[k], y_mm[k], z_mm[k]);
    // A float's rounding can put a position in the next cell: look at the neighbours too.
    for (int dx = -1; dx <= 1 && index_[k] < 0; ++dx)
      for (int dy = -1; dy <= 1 && index_[k] < 0; ++dy)
        for (int dz = -1; dz <= 1 && index_[k] < 0; ++dz) {
          auto it = at.find({std::get<0>(c) + dx, std::get<1>(c) + dy, std::get<2>(c) + dz});
          if (it != at.end()) index_[k] = it->second;
        }
    if (index_[k] >= 0) ++matched_;
  }
  if (n > 0) first_xyz_ = {x_mm[0], y_mm[0], z_mm[0]};
  return index_;
}

}  // namespace sedbridge::view
