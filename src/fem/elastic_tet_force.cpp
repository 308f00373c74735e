#include "fem/elastic_tet_force.h"

#include <cstdint>
#include <stdexcept>

#include "fem/rotation_extraction.h"

namespace sedbridge::fem {

std::vector<std::vector<int>> ColorElements(const std::vector<Tet>& tets, int num_nodes) {
  // Bit masks of colours used around each node; meshes of tets need ~20-40 colours, the
  // overflow path handles more.
  std::vector<std::vector<int>> colors;
  std::vector<std::vector<uint64_t>> used(size_t(num_nodes), std::vector<uint64_t>(1, 0));
  for (int t = 0; t < int(tets.size()); ++t) {
    int c = 0;
    for (;; ++c) {
      const size_t word = size_t(c / 64);
      const uint64_t bit = uint64_t(1) << (c % 64);
      bool free = true;
      for (int n : tets[size_t(t)])
        if (word < used[size_t(n)].size() && (used[size_t(n)][word] & bit)) free = false;
      if (free) break;
    }
    for (int n : tets[size_t(t)]) {
      auto& u = used[size_t(n)];
      if (u.size() <= size_t(c / 64)) u.resize(size_t(c / 64) + 1, 0);
      u[size_t(c / 64)] |= uint64_t(1) << (c % 64);
    }
    if (colors.size() <= size_t(c)) colors.resize(size_t(c) + 1);
    colors[size_t(c)].push_back(t);
  }
  return colors;
}

ElasticTetForce::ElasticTetForce(const TetMesh& mesh, ElasticFormulation formulation,
                                 double rayleigh_beta_s)
    : mesh_(mesh), formulation_(formulation), beta_s_(rayleigh_beta_s) {
  elements_ = PrecomputeElements(mesh);
  colors_ = ColorElements(mesh.tets, mesh.num_nodes());
  quaternions_.assign(elements_.size(), Eigen::Quaterniond::Identity());
  rotations_.assign(elements_.size(), Eigen::Matrix3d::Identity());
  node_elements_.resize(size_t(mesh.num_nodes()));
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int n : mesh.tets[size_t(t)]) node_elements_[size_t(n)].push_back(t);
}

std::string ElasticTetForce::name() const {
  return formulation_ == ElasticFormulation::kCorotational ? "elastic_corotational" : "elastic_linear";
}

void ElasticTetForce::AppendCoupledNodes(std::vector<std::pair<int, int>>& pairs) const {
  for (const Tet& t : mesh_.tets)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) pairs.emplace_back(t[size_t(a)], t[size_t(b)]);
}

void ElasticTetForce::BindMatrix(const SystemMatrix& matrix) {
  slots_.resize(elements_.size());
  for (size_t t = 0; t < elements_.size(); ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) slots_[t][size_t(4 * a + b)] = matrix.Slot(mesh_.tets[t][size_t(a)], mesh_.tets[t][size_t(b)]);
}

void ElasticTetForce::AddForce(const SystemState& state, Eigen::VectorXd& force_N, JacobianSink* sink) {
  if (sink && slots_.empty()) throw std::logic_error("ElasticTetForce: BindMatrix not called");
  const bool corotational = formulation_ == ElasticFormulation::kCorotational;
  const bool damping = state.dynamic && beta_s_ > 0;
  int inverted = 0;
  for (const auto& color : colors_) {
#pragma omp parallel for schedule(static) reduction(+ : inverted)
    for (int k = 0; k < int(color.size()); ++k) {
      const int t = color[size_t(k)];
      const TetElement& e = elements_[size_t(t)];
      const Tet& n = mesh_.tets[size_t(t)];
      Eigen::Vector3d x[4];
      for (int a = 0; a < 4; ++a) x[a] = state.x_m.segment<3>(3 * n[size_t(a)]);
      const Eigen::Matrix3d F = DeformationGradient(e, x[0], x[1], x[2], x[3]);
      if (F.determinant() <= 0) ++inverted;
      Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
      if (corotational) R = ExtractRotation(F, quaternions_[size_t(t)]);
      rotations_[size_t(t)] = R;

      // f = -R K0 (R^T x - X)
      Eigen::Matrix<double, 12, 1> u;
      for (int a = 0; a < 4; ++a)
        u.segment<3>(3 * a) = R.transpose() * x[a] - mesh_.rest_positions_m.col(n[size_t(a)]);
      Eigen::Matrix<double, 12, 1> g = e.rest_stiffness * u;
      if (damping) {
        Eigen::Matrix<double, 12, 1> w;
        for (int a = 0; a < 4; ++a) w.segment<3>(3 * a) = R.transpose() * state.v_m_s.segment<3>(3 * n[size_t(a)]);
        g += beta_s_ * (e.rest_stiffness * w);
      }
      for (int a = 0; a < 4; ++a) force_N.segment<3>(3 * n[size_t(a)]) -= R * g.segment<3>(3 * a);

      if (!sink) continue;
      for (int a = 0; a < 4; ++a) {
        for (int b = a; b < 4; ++b) {
          const Eigen::Matrix3d K = R * e.rest_stiffness.block<3, 3>(3 * a, 3 * b) * R.transpose();
          const Eigen::Matrix3d D = beta_s_ * K;
          sink->Add(slots_[size_t(t)][size_t(4 * a + b)], n[size_t(a)], n[size_t(b)], K, damping ? &D : nullptr);
          if (b != a) {
            const Eigen::Matrix3d Kt = K.transpose();
            const Eigen::Matrix3d Dt = beta_s_ * Kt;
            sink->Add(slots_[size_t(t)][size_t(4 * b + a)], n[size_t(b)], n[size_t(a)], Kt, damping ? &Dt : nullptr);
          }
        }
      }
    }
  }
  inverted_elements_ = inverted;
}

double ElasticTetForce::PotentialEnergy(const SystemState& state) const {
  double energy = 0;
  for (size_t t = 0; t < elements_.size(); ++t) {
    const Tet& n = mesh_.tets[t];
    Eigen::Matrix<double, 12, 1> u;
    for (int a = 0; a < 4; ++a)
      u.segment<3>(3 * a) = rotations_[t].transpose() * state.x_m.segment<3>(3 * n[size_t(a)]) -
                            mesh_.rest_positions_m.col(n[size_t(a)]);
    energy += 0.5 * u.dot(elements_[t].rest_stiffness * u);
  }
  return energy;
}

void ElasticTetForce::ComputeNodeRotations(std::vector<Eigen::Matrix3d>& node_rotations) const {
  node_rotations.resize(node_elements_.size());
#pragma omp parallel for schedule(static)
  for (int i = 0; i < int(node_elements_.size()); ++i) {
    Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
    for (int t : node_elements_[size_t(i)]) sum += rotations_[size_t(t)];
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    node_rotations[size_t(i)] = ExtractRotation(sum, q);
  }
}

}  // namespace sedbridge::fem
