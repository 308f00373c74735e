#include "fem/surface_traction_force.h"

#include <Eigen/Dense>
#include <algorithm>
#include <map>
#include <stdexcept>

namespace sedbridge::fem {

SurfaceTractionForce::SurfaceTractionForce(const Eigen::Matrix3Xd& x, std::vector<Triangle> triangles) {
  for (const Triangle& t : triangles) nodes_.insert(nodes_.end(), t.begin(), t.end());
  std::sort(nodes_.begin(), nodes_.end());
  nodes_.erase(std::unique(nodes_.begin(), nodes_.end()), nodes_.end());
  auto local = [&](int n) { return int(std::lower_bound(nodes_.begin(), nodes_.end(), n) - nodes_.begin()); };
  std::vector<std::map<int, double>> rows(nodes_.size());
  for (const Triangle& t : triangles) {
    const double area = 0.5 * (x.col(t[1]) - x.col(t[0])).cross(x.col(t[2]) - x.col(t[0])).norm();
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) rows[size_t(local(t[size_t(a)]))][local(t[size_t(b)])] += area / 12.0 * (a == b ? 2.0 : 1.0);
  }
  row_start_.push_back(0);
  for (const auto& r : rows) {
    for (const auto& [j, w] : r) weights_.emplace_back(j, w);
    row_start_.push_back(int(weights_.size()));
  }
  node_rest_positions_m_.resize(3, Eigen::Index(nodes_.size()));
  for (size_t k = 0; k < nodes_.size(); ++k) node_rest_positions_m_.col(Eigen::Index(k)) = x.col(nodes_[k]);
  traction_Pa_ = Eigen::Matrix3Xd::Zero(3, Eigen::Index(nodes_.size()));
}

void SurfaceTractionForce::SetNodalTraction(const Eigen::Matrix3Xd& traction) {
  if (traction.cols() != traction_Pa_.cols())
    throw std::invalid_argument("traction has " + std::to_string(traction.cols()) + " columns, expected " +
                                std::to_string(traction_Pa_.cols()));
  if (!traction.allFinite()) throw std::invalid_argument("traction contains NaN or Inf");
  traction_Pa_ = traction;
}

Eigen::Matrix3Xd SurfaceTractionForce::NodalForces() const {
  Eigen::Matrix3Xd out(3, traction_Pa_.cols());
  for (Eigen::Index k = 0; k < out.cols(); ++k) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int w = row_start_[size_t(k)]; w < row_start_[size_t(k) + 1]; ++w)
      sum += weights_[size_t(w)].second * traction_Pa_.col(weights_[size_t(w)].first);
    out.col(k) = sum;
  }
  return out;
}

void SurfaceTractionForce::AddForce(const SystemState&, Eigen::VectorXd& f, JacobianSink*) {
  const Eigen::Matrix3Xd nodal = NodalForces();
  for (size_t k = 0; k < nodes_.size(); ++k) f.segment<3>(3 * nodes_[k]) += nodal.col(Eigen::Index(k));
}

Eigen::Vector3d SurfaceTractionForce::TotalForce() const { return NodalForces().rowwise().sum(); }

}  // namespace sedbridge::fem
