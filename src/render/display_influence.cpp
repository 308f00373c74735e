#include "render/display_influence.h"

#include <stdexcept>

namespace sedbridge::render {

namespace {

// The element's SED as a quadratic form in its strain: W = eps^T M eps with
// W = mu eps:eps + lambda/2 tr(eps)^2 (shear components count twice in eps:eps).
Eigen::Matrix<double, kStrainComponents, kStrainComponents> SedForm(double mu_Pa, double lambda_Pa) {
  Eigen::Matrix<double, kStrainComponents, kStrainComponents> M = Eigen::Matrix<double, 6, 6>::Zero();
  for (int i = 0; i < 3; ++i) {
    M(i, i) = mu_Pa;
    for (int j = 0; j < 3; ++j) M(i, j) += 0.5 * lambda_Pa;
  }
  for (int i = 3; i < 6; ++i) M(i, i) = 2.0 * mu_Pa;
  return M;
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
    const Eigen::Matrix<double, kStrainComponents, 1> eps = eps_.segment<kStrainComponents>(kStrainComponents * e);
    element_sed_[e] = eps.dot(SedForm(in_.mu_Pa[e], in_.lambda_Pa[e]) * eps);
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
        2.0 * SedForm(in_.mu_Pa[e], in_.lambda_Pa[e]) * eps_.segment<kStrainComponents>(kStrainComponents * e);
    element_gradient_.row(e).noalias() = g.transpose() * in_.strain_per_command.middleRows<kStrainComponents>(kStrainComponents * e);
  }
  jacobian.setZero(num_vertices(), num_actuators_);
  for (int v = 0; v < num_vertices(); ++v)
    for (int k = in_.vertex_start[size_t(v)]; k < in_.vertex_start[size_t(v) + 1]; ++k)
      jacobian.row(v) += in_.vertex_weight[size_t(k)] * element_gradient_.row(in_.vertex_element[size_t(k)]);
}

}  // namespace sedbridge::render
