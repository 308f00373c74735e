#include "scene/merkel_layer.h"

#include <Eigen/Dense>
#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "fem/mesh_topology.h"

namespace sedbridge::scene {
namespace {

// A pad-facing triangle whose projection onto the pad plane has |2 x area| below this
// [mm^2] is seen edge-on: it holds no path point, and its barycentrics would be noise.
constexpr double kEdgeOnTriangleDet_mm2 = 1e-12;
// Barycentric slack [-]: a path point on a shared edge belongs to both triangles, so that
// round-off cannot drop it from either.
constexpr double kBarycentricSlack = 1e-9;
// Relative slack on the sample count [-]: (x_max - x_min) / step a hair below an integer
// still samples x_max.
constexpr double kSampleCountSlack = 1e-9;

}  // namespace

// Per soft tet: 1 where its material is the named side (empty for both sides).
std::vector<char> SideMask(const model::FingertipModel& model, MerkelSide side) {
  if (side == MerkelSide::kBoth) return {};
  const std::string name = config::NameOf(side);
  std::vector<char> mask(model.soft.tets.size(), 0);
  bool found = false;
  for (size_t t = 0; t < mask.size(); ++t)
    if (model.soft.materials[size_t(model.soft.tet_material[t])].name == name) mask[t] = found = true;
  if (!found) throw std::invalid_argument("merkel_side: model '" + model.name + "' has no '" + name + "' material");
  return mask;
}

MerkelLayer::MerkelLayer(const model::FingertipModel& model, const fem::ElasticTetForce& elastic,
                         const fem::NodalPressureTetForce* nodal, MerkelSide side)
    : side_mask_(SideMask(model, side)),
      evaluator_(elastic, model.merkel_nodes, nodal, side_mask_.empty() ? nullptr : &side_mask_) {
  const auto& x = model.soft.rest_positions_m;
  const size_t n = model.merkel_nodes.size();
  rest_pad_mm_.resize(3, Eigen::Index(n));
  std::unordered_map<int, int> local;
  for (size_t k = 0; k < n; ++k) {
    local[model.merkel_nodes[k]] = int(k);
    rest_pad_mm_.col(Eigen::Index(k)) = model.pad_frame.ToPad(x.col(model.merkel_nodes[k])) * 1e3;
  }
  const Eigen::Vector3d z_pad = model.pad_frame.model_from_pad.linear().col(2);
  const auto normals = fem::VertexNormals(model.merkel_triangles, x, model.merkel_nodes);
  facing_pad_.resize(n);
  for (size_t k = 0; k < n; ++k) facing_pad_[k] = normals[k].dot(z_pad) > 0 ? 1 : 0;
  for (const auto& t : model.merkel_triangles) {
    const Eigen::Vector3d normal = (x.col(t[1]) - x.col(t[0])).cross(x.col(t[2]) - x.col(t[0]));
    if (normal.dot(z_pad) > 0) pad_triangles_.push_back({local[t[0]], local[t[1]], local[t[2]]});
  }
  sed_Pa_ = Eigen::VectorXd::Zero(Eigen::Index(n));
}

const Eigen::VectorXd& MerkelLayer::Evaluate(const Eigen::VectorXd& x_m) {
  evaluator_.Evaluate(x_m, sed_Pa_);
  return sed_Pa_;
}

std::vector<PathSample> MerkelLayer::SamplePath(const Eigen::VectorXd& sed, double y, double x_min,
                                                double x_max, double step) const {
  std::vector<PathSample> out;
  const int count = int(std::floor((x_max - x_min) / step + kSampleCountSlack)) + 1;
  for (int s = 0; s < count; ++s) {
    const double px = x_min + s * step;
    double best_z = -std::numeric_limits<double>::infinity();
    double value = 0;
    for (const auto& t : pad_triangles_) {
      const Eigen::Vector3d a = rest_pad_mm_.col(t[0]), b = rest_pad_mm_.col(t[1]), c = rest_pad_mm_.col(t[2]);
      const double det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
      if (std::abs(det) < kEdgeOnTriangleDet_mm2) continue;
      const double l1 = ((px - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (y - a.y())) / det;
      const double l2 = ((b.x() - a.x()) * (y - a.y()) - (px - a.x()) * (b.y() - a.y())) / det;
      const double l0 = 1 - l1 - l2;
      if (l0 < -kBarycentricSlack || l1 < -kBarycentricSlack || l2 < -kBarycentricSlack) continue;
      const double z = l0 * a.z() + l1 * b.z() + l2 * c.z();
      if (z > best_z) {  // the sheet nearest the pressing plane
        best_z = z;
        value = l0 * sed[t[0]] + l1 * sed[t[1]] + l2 * sed[t[2]];
      }
    }
    if (std::isfinite(best_z)) out.push_back({px, value});
  }
  return out;
}

}  // namespace sedbridge::scene
