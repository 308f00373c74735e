#include "render/display_influence.h"

#include <stdexcept>

#include "fem/tet_sed.h"

namespace sedbridge::render {

namespace {

// dW/deps of W = mu eps:eps + lambda/2 tr(eps)^2 in this file's component order (the shear
// components count twice in eps:eps): 2 mu eps_ii + lambda tr, and 4 mu eps_ij.
Eigen::Matrix<double, kStrainComponents, 1> SedGradient(const double* eps, double mu_Pa, double lambda_Pa) {
  const double tr = eps[0] + eps[1] + eps[2];
  Eigen::Matrix<double, kStrainComponents, 1> g;
  for (int i = 0; i < 3; ++i) g[i] = 2.0 * mu_Pa * eps[i] + lambda_Pa * tr;
  for (int i = 3; i < 6; ++i) g[i] = 4.0 * mu_Pa * eps[i];
  return g;
}

void CheckSizes(const ElementStrainInfluence& in) {
  const Eigen::Index elements = in.mu_Pa.size();
  const bool sizes = in.lambda_Pa.size() == elements && in.preload_strain.size() == kStrainComponents * elements &&
                     in.strain_per_command.rows() == kStrainComponents * elements && !in.vertex_start.empty() &&
                     in.vertex_start.front() == 0 && size_t(in.vertex_start.back()) == in.vertex_element.size() &&
                     in.vertex_element.size() == in.vertex_weight.size();
  if (!sizes) throw std::invalid_argument("display influence: inconsistent sizes");
  for (size_t v = 0; v + 1 < in.vertex_start.size(); ++v)
    if (in.vertex_start[v] > in.vertex_start[v + 1]) throw std::invalid_argument("display influence: vertex ranges out of order");
  for (int e : in.vertex_element)
    if (e < 0 || e >= elements) throw std::invalid_argument("display influence: a vertex names no element");
  if (!in.strain_per_command.allFinite() || !in.preload_strain.allFinite() || !in.mu_Pa.allFinite() ||
      !in.lambda_Pa.allFinite())
    throw std::invalid_argument("display influence: non-finite strain or material");
}

}  // namespace

DisplayInfluence::DisplayInfluence(const ElementStrainInfluence& elements) : in_(elements) {
  CheckSizes(in_);
  num_actuators_ = int(in_.strain_per_command.cols());
  ElementSeds(Eigen::VectorXd::Zero(num_actuators_));
  AverageToVertices(element_sed_, preload_sed_Pa_);
}

void DisplayInfluence::ElementSeds(const Eigen::VectorXd& u) const {
  eps_ = in_.preload_strain;
  eps_.noalias() += in_.strain_per_command * u;
  const Eigen::Index elements = in_.mu_Pa.size();
  element_sed_.resize(elements);
  for (Eigen::Index e = 0; e < elements; ++e) {
    const double* eps = eps_.data() + kStrainComponents * e;
    fem::SymmetricStrainSed<double>(eps[0], eps[1], eps[2], eps[3], eps[4], eps[5], in_.mu_Pa[e], in_.lambda_Pa[e],
                                    element_sed_[e]);
  }
}

void DisplayInfluence::AverageToVertices(const Eigen::VectorXd& element, Eigen::VectorXd& vertex) const {
  const int vertices = num_vertices();
  vertex.setZero(vertices);
  for (int v = 0; v < vertices; ++v)
    for (int k = in_.vertex_start[size_t(v)]; k < in_.vertex_start[size_t(v) + 1]; ++k)
      vertex[v] += in_.vertex_weight[size_t(k)] * element[in_.vertex_element[size_t(k)]];
}

void DisplayInfluence::Sed(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa) const {
  ElementSeds(u);
  AverageToVertices(element_sed_, sed_Pa);
}

void DisplayInfluence::SedAndJacobian(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa, Eigen::MatrixXd& jacobian) const {
  ElementSeds(u);
  AverageToVertices(element_sed_, sed_Pa);
  // dW_e/du = 2 (M_e eps_e)^T E_e, then averaged as the SED is.
  const Eigen::Index elements = in_.mu_Pa.size();
  element_gradient_.resize(elements, num_actuators_);
  for (Eigen::Index e = 0; e < elements; ++e) {
    const Eigen::Matrix<double, kStrainComponents, 1> g =
        SedGradient(eps_.data() + kStrainComponents * e, in_.mu_Pa[e], in_.lambda_Pa[e]);
    element_gradient_.row(e).noalias() = g.transpose() * in_.strain_per_command.middleRows<kStrainComponents>(kStrainComponents * e);
  }
  jacobian.setZero(num_vertices(), num_actuators_);
  for (int v = 0; v < num_vertices(); ++v)
    for (int k = in_.vertex_start[size_t(v)]; k < in_.vertex_start[size_t(v) + 1]; ++k)
      jacobian.row(v) += in_.vertex_weight[size_t(k)] * element_gradient_.row(in_.vertex_element[size_t(k)]);
}

}  // namespace sedbridge::render
