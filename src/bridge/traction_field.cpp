#include "bridge/traction_field.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bridge/taxel_values.h"

namespace sedbridge::bridge {

bool InsideFootprint(const sensors::SensorProfile& profile, const Eigen::Vector2d& s) {
  if (profile.taxels.empty()) return false;
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const auto& t : profile.taxels) {
    x0 = std::min(x0, t.x_mm), x1 = std::max(x1, t.x_mm);
    y0 = std::min(y0, t.y_mm), y1 = std::max(y1, t.y_mm);
  }
  const double hx = 0.5 * profile.taxel_width_mm, hy = 0.5 * profile.taxel_height_mm;
  return s.x() >= x0 - hx && s.x() <= x1 + hx && s.y() >= y0 - hy && s.y() <= y1 + hy;
}

TractionWeights BuildTractionWeights(const sensors::SensorProfile& profile, const PadRegistration& registration,
                                     const SkinNodes& nodes, const TractionFieldOptions& options) {
  TractionWeights out;
  const int num_taxels = profile.taxel_count;
  const int num_nodes = static_cast<int>(nodes.position_pad_mm.cols());
  double sigma = options.kernel_sigma_mm;
  if (!(sigma > 0)) sigma = 0.5 * SmallestTaxelSpacing_mm(profile.taxels);
  if (!(sigma > 0)) sigma = std::max(1.0, 0.5 * std::max(profile.taxel_width_mm, profile.taxel_height_mm));
  out.sigma_mm = sigma;

  // Shepard rows first, then per-taxel column scaling for the force balance.
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd column_area = Eigen::VectorXd::Zero(num_taxels);  // sum_n a_n w_ni
  std::vector<double> g(static_cast<size_t>(num_taxels));
  for (int n = 0; n < num_nodes; ++n) {
    const Eigen::Vector3d p = nodes.position_pad_mm.col(n);
    if (nodes.normal_pad(2, n) < options.min_facing || p.z() < -options.max_depth_mm) continue;
    const Eigen::Vector2d s = registration.ToSensor(p.head<2>());
    if (!InsideFootprint(profile, s)) continue;
    double sum = 0;
    for (int i = 0; i < num_taxels; ++i) {
      const double dx = s.x() - profile.taxels[size_t(i)].x_mm, dy = s.y() - profile.taxels[size_t(i)].y_mm;
      g[size_t(i)] = std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma));
      sum += g[size_t(i)];
    }
    if (!(sum > 0)) {  // far from every taxel in kernel units: nearest taxel takes it
      int best = 0;
      double best_d = std::numeric_limits<double>::infinity();
      for (int i = 0; i < num_taxels; ++i) {
        const double d = std::hypot(s.x() - profile.taxels[size_t(i)].x_mm, s.y() - profile.taxels[size_t(i)].y_mm);
        if (d < best_d) best_d = d, best = i;
      }
      std::fill(g.begin(), g.end(), 0.0);
      g[size_t(best)] = sum = 1;
    }
    out.loaded_nodes.push_back(n);
    out.loaded_area_m2 += nodes.area_m2[n];
    for (int i = 0; i < num_taxels; ++i) {
      const double w = g[size_t(i)] / sum;
      if (w < 1e-9) continue;  // sparsity; the balance below stays exact for what is kept
      entries.emplace_back(n, i, w);
      column_area[i] += nodes.area_m2[n] * w;
    }
  }
  const double scale = registration.params().scale;
  const double taxel_area_m2 = profile.taxel_area_mm2() * 1e-6 * scale * scale;
  for (auto& e : entries) {
    const int i = e.col();
    e = Eigen::Triplet<double>(e.row(), i, e.value() * taxel_area_m2 / column_area[i]);
  }
  for (int i = 0; i < num_taxels; ++i)
    if (!(column_area[i] > 0)) out.unmapped_taxels.push_back(i);
  out.W.resize(num_nodes, num_taxels);
  out.W.setFromTriplets(entries.begin(), entries.end());
  out.W.makeCompressed();
  return out;
}

}  // namespace sedbridge::bridge
