#include "fem/strain_energy_density.h"

#include <algorithm>
#include <map>

#include "fem/rotation_extraction.h"

namespace sedbridge::fem {

// A Merkel layer has a few thousand elements (~0.3 ms): not worth a parallel region.
constexpr size_t kParallelMinElements = 20000;

double ElementSed(const TetElement& e, const Eigen::Matrix3d& F, const Eigen::Matrix3d& R) {
  const Eigen::Matrix3d G = R.transpose() * F;
  const Eigen::Matrix3d eps = 0.5 * (G + G.transpose()) - Eigen::Matrix3d::Identity();
  const double tr = eps.trace();
  const Eigen::Matrix3d sigma = e.lambda_Pa * tr * Eigen::Matrix3d::Identity() + 2.0 * e.mu_Pa * eps;
  return 0.5 * (sigma.array() * eps.array()).sum();
}

VertexSedEvaluator::VertexSedEvaluator(const ElasticTetForce& elastic, std::vector<int> vertices)
    : elastic_(elastic), vertices_(std::move(vertices)) {
  const TetMesh& mesh = elastic.mesh();
  std::vector<std::vector<int>> node_elements(size_t(mesh.num_nodes()));
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int n : mesh.tets[size_t(t)]) node_elements[size_t(n)].push_back(t);
  std::map<int, int> local;
  for (int v : vertices_)
    for (int t : node_elements.at(size_t(v))) local.emplace(t, 0);
  for (auto& [t, k] : local) {
    k = int(elements_.size());
    elements_.push_back(t);
  }
  for (int v : vertices_) {
    std::vector<int> ids;
    for (int t : node_elements[size_t(v)]) ids.push_back(local[t]);
    vertex_local_.push_back(std::move(ids));
  }
  warm_.assign(elements_.size(), Eigen::Quaterniond::Identity());
  element_sed_ = Eigen::VectorXd::Zero(Eigen::Index(elements_.size()));
}

void VertexSedEvaluator::Evaluate(const Eigen::VectorXd& x, Eigen::VectorXd& vertex_sed) {
  const TetMesh& mesh = elastic_.mesh();
  const bool corotational = elastic_.formulation() == ElasticFormulation::kCorotational;
#pragma omp parallel for schedule(static) if (elements_.size() > kParallelMinElements)
  for (int k = 0; k < int(elements_.size()); ++k) {
    const int t = elements_[size_t(k)];
    const Tet& n = mesh.tets[size_t(t)];
    const TetElement& e = elastic_.elements()[size_t(t)];
    const Eigen::Matrix3d F = DeformationGradient(e, x.segment<3>(3 * n[0]), x.segment<3>(3 * n[1]),
                                                  x.segment<3>(3 * n[2]), x.segment<3>(3 * n[3]));
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    if (corotational) R = ExtractRotation(F, warm_[size_t(k)]);
    element_sed_[k] = ElementSed(e, F, R);
  }
  AverageToVertices(element_sed_, vertex_sed);
}

void VertexSedEvaluator::AverageToVertices(const Eigen::VectorXd& element_sed, Eigen::VectorXd& vertex_sed) const {
  vertex_sed.resize(Eigen::Index(vertices_.size()));
  for (size_t v = 0; v < vertices_.size(); ++v) {
    double sum = 0;
    for (int k : vertex_local_[v]) sum += element_sed[k];
    vertex_sed[Eigen::Index(v)] = vertex_local_[v].empty() ? 0.0 : sum / double(vertex_local_[v].size());
  }
}

}  // namespace sedbridge::fem
