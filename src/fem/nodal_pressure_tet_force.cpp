#include "fem/nodal_pressure_tet_force.h"

#include <omp.h>

#include <algorithm>
#include <map>
#include <stdexcept>

namespace sedbridge::fem {
namespace {
// Fewer elements than this: one thread (a team costs more than it brings).
constexpr int kParallelMinTets = 256;
}  // namespace

NodalPressureTetForce::NodalPressureTetForce(const ElasticTetForce& elastic, double rayleigh_beta_s)
    : elastic_(elastic), beta_s_(rayleigh_beta_s) {
  if (!elastic.deviatoric_only())
    throw std::invalid_argument("NodalPressureTetForce: the elastic term must be deviatoric-only");
  const TetMesh& mesh = elastic.mesh();
  const auto& elements = elastic.elements();
  const int num_tets = mesh.num_tets();
  // One patch per (node, material) pair that occurs.
  std::map<std::pair<int, int>, int> patch_id;
  element_patch_.resize(size_t(num_tets));
  for (int t = 0; t < num_tets; ++t) {
    const int m = mesh.tet_material.at(size_t(t));
    for (int a = 0; a < 4; ++a) {
      auto it = patch_id.emplace(std::make_pair(mesh.tets[size_t(t)][size_t(a)], m), int(patch_id.size())).first;
      element_patch_[size_t(t)][size_t(a)] = it->second;
    }
  }
  const int np = int(patch_id.size());
  patch_volume_.assign(size_t(np), 0.0);
  patch_bulk_.assign(size_t(np), 0.0);
  std::vector<std::vector<int>> members(static_cast<size_t>(np));
  for (int t = 0; t < num_tets; ++t) {
    const TetElement& e = elements[size_t(t)];
    // The elastic term replaced lambda by -2 mu / 3; the bulk modulus comes from the material.
    const auto& mat = mesh.materials.at(size_t(mesh.tet_material.at(size_t(t))));
    const double kappa = mat.lame_lambda_Pa() + 2.0 * mat.lame_mu_Pa() / 3.0;
    for (int a = 0; a < 4; ++a) {
      const int p = element_patch_[size_t(t)][size_t(a)];
      patch_volume_[size_t(p)] += e.volume_m3 / 4.0;
      patch_bulk_[size_t(p)] = kappa;
      members[size_t(p)].push_back(t);
    }
  }
  patch_offsets_.assign(1, 0);
  node_offsets_.assign(1, 0);
  for (int p = 0; p < np; ++p) {
    std::vector<int> nodes;
    for (int t : members[size_t(p)]) {
      patch_elements_.push_back(t);
      for (int n : mesh.tets[size_t(t)]) nodes.push_back(n);
    }
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    for (int t : members[size_t(p)]) {
      std::array<int, 4> local{};
      for (int a = 0; a < 4; ++a)
        local[size_t(a)] = int(std::lower_bound(nodes.begin(), nodes.end(), mesh.tets[size_t(t)][size_t(a)]) - nodes.begin());
      entry_local_.push_back(local);
    }
    patch_nodes_.insert(patch_nodes_.end(), nodes.begin(), nodes.end());
    patch_offsets_.push_back(int(patch_elements_.size()));
    node_offsets_.push_back(int(patch_nodes_.size()));
  }
  element_theta_ = Eigen::VectorXd::Zero(num_tets);
  patch_theta_ = Eigen::VectorXd::Zero(np);
  patch_pressure_ = Eigen::VectorXd::Zero(np);
}

double NodalPressureTetForce::ElementVolumetricStrain(const Eigen::Matrix3d& F, const Eigen::Matrix3d& R) {
  return (R.array() * F.array()).sum() - 3.0;  // tr(R^T F) - 3
}

void NodalPressureTetForce::AppendCoupledNodes(std::vector<std::pair<int, int>>& pairs) const {
  for (int p = 0; p < num_patches(); ++p)
    for (int i = node_offsets_[size_t(p)]; i < node_offsets_[size_t(p) + 1]; ++i)
      for (int j = i + 1; j < node_offsets_[size_t(p) + 1]; ++j) pairs.emplace_back(patch_nodes_[size_t(i)], patch_nodes_[size_t(j)]);
}

void NodalPressureTetForce::BindMatrix(const SystemMatrix& matrix) {
  slot_offsets_.assign(1, 0);
  slots_.clear();
  size_t widest = 0;
  for (int p = 0; p < num_patches(); ++p) {
    const int begin = node_offsets_[size_t(p)], end = node_offsets_[size_t(p) + 1];
    widest = std::max(widest, size_t(end - begin));
    for (int i = begin; i < end; ++i)
      for (int j = begin; j < end; ++j) slots_.push_back(matrix.Slot(patch_nodes_[size_t(i)], patch_nodes_[size_t(j)]));
    slot_offsets_.push_back(int(slots_.size()));
  }
  widest_patch_ = widest;
  partition_ = {};  // rebuilt for the team size at the next assembly
  thread_b_.clear();
  // The element blocks for the twist terms of the consistent tangent.
  element_slots_.clear();
  if (elastic_.formulation() == ElasticFormulation::kCorotational) {
    const TetMesh& mesh = elastic_.mesh();
    element_slots_.resize(size_t(mesh.num_tets()));
    for (int t = 0; t < mesh.num_tets(); ++t)
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
          element_slots_[size_t(t)][size_t(4 * a + b)] = matrix.Slot(mesh.tets[size_t(t)][size_t(a)], mesh.tets[size_t(t)][size_t(b)]);
  }
}

bool NodalPressureTetForce::UseDefiniteJacobian(bool definite) {
  if (elastic_.formulation() != ElasticFormulation::kCorotational ||
      elastic_.corotational_tangent() != CorotationalTangent::kConsistent)
    return false;
  definite_ = definite;
  return true;
}

void NodalPressureTetForce::PatchStrains(const Eigen::VectorXd& element_theta, Eigen::VectorXd& patch_theta) const {
  const auto& elements = elastic_.elements();
  patch_theta.setZero(num_patches());
#pragma omp parallel for schedule(static) if (num_patches() >= kParallelMinTets)
  for (int p = 0; p < num_patches(); ++p) {
    double sum = 0;
    for (int k = patch_offsets_[size_t(p)]; k < patch_offsets_[size_t(p) + 1]; ++k)
      sum += elements[size_t(patch_elements_[size_t(k)])].volume_m3 * element_theta[patch_elements_[size_t(k)]];
    patch_theta[p] = sum / (4.0 * patch_volume_[size_t(p)]);
  }
}

void NodalPressureTetForce::AddPatchJacobian(int p, bool damping, JacobianSink* sink, std::vector<Eigen::Vector3d>& b) {
  const auto& elements = elastic_.elements();
  const auto& rotations = elastic_.rotations();
  double* values = sink->matrix->values();
  const int n0 = node_offsets_[size_t(p)], np = node_offsets_[size_t(p) + 1] - n0;
  for (int i = 0; i < np; ++i) b[size_t(i)].setZero();
  for (int k = patch_offsets_[size_t(p)]; k < patch_offsets_[size_t(p) + 1]; ++k) {
    const int t = patch_elements_[size_t(k)];
    const TetElement& e = elements[size_t(t)];
    const double w = e.volume_m3 / (4.0 * patch_volume_[size_t(p)]);
    const Eigen::Matrix3d& R = rotations[size_t(t)];
    for (int a = 0; a < 4; ++a) b[size_t(entry_local_[size_t(k)][size_t(a)])] += w * (R * e.shape_gradients.row(a).transpose());
  }
  const double c = patch_volume_[size_t(p)] * patch_bulk_[size_t(p)];
  const int* slots = slots_.data() + slot_offsets_[size_t(p)];
  // Symmetric: each off-diagonal outer product once, written to (i, j) and (j, i), with its
  // stiffness-proportional damping (D = beta K) in the same pass.
  const double scale = sink->stiffness_scale + (damping ? beta_s_ * sink->damping_scale : 0.0);
  for (int i = 0; i < np; ++i) {
    const Eigen::Vector3d bi = c * b[size_t(i)];
    for (int j = i; j < np; ++j) {
      const Eigen::Matrix3d K = bi * b[size_t(j)].transpose();
      sink->matrix->AddBlockTo(values, slots[i * np + j], K, scale);
      if (j != i) sink->matrix->AddBlockTo(values, slots[j * np + i], K.transpose(), scale);
    }
  }
  if (sink->velocity) {
    // The patch's K is c b b^T: K v = c b (b . v), one dot product instead of np^2 blocks.
    const Eigen::VectorXd& v = *sink->velocity;
    double bv = 0;
    for (int j = 0; j < np; ++j) bv += b[size_t(j)].dot(v.segment<3>(3 * patch_nodes_[size_t(n0 + j)]));
    for (int i = 0; i < np; ++i)
      sink->stiffness_times_velocity->segment<3>(3 * patch_nodes_[size_t(n0 + i)]) += (c * bv) * b[size_t(i)];
  }
}

void NodalPressureTetForce::AddForce(const SystemState& state, Eigen::VectorXd& force_N, JacobianSink* sink) {
  if (sink && slot_offsets_.size() != size_t(num_patches()) + 1)
    throw std::logic_error("NodalPressureTetForce: BindMatrix not called");
  const TetMesh& mesh = elastic_.mesh();
  const auto& elements = elastic_.elements();
  const auto& rotations = elastic_.rotations();
  const bool damping = state.dynamic && beta_s_ > 0;
  const int num_tets = mesh.num_tets();
  // Element volumetric strain (+ beta times its rate: stiffness-proportional damping).
#pragma omp parallel for schedule(static) if (num_tets >= kParallelMinTets)
  for (int t = 0; t < num_tets; ++t) {
    const Tet& n = mesh.tets[size_t(t)];
    const TetElement& e = elements[size_t(t)];
    const Eigen::Vector3d x0 = state.x_m.segment<3>(3 * n[0]);
    const Eigen::Matrix3d F = DeformationGradient(e, x0, state.x_m.segment<3>(3 * n[1]), state.x_m.segment<3>(3 * n[2]),
                                                  state.x_m.segment<3>(3 * n[3]));
    double theta = ElementVolumetricStrain(F, rotations[size_t(t)]);
    if (damping) {
      const Eigen::Vector3d v0 = state.v_m_s.segment<3>(3 * n[0]);
      const Eigen::Matrix3d Fd = DeformationGradient(e, v0, state.v_m_s.segment<3>(3 * n[1]),
                                                     state.v_m_s.segment<3>(3 * n[2]), state.v_m_s.segment<3>(3 * n[3]));
      theta += beta_s_ * (rotations[size_t(t)].array() * Fd.array()).sum();  // tr(R^T dF/dt)
    }
    element_theta_[t] = theta;
  }
  PatchStrains(element_theta_, patch_theta_);
  for (int p = 0; p < num_patches(); ++p) patch_pressure_[p] = patch_bulk_[size_t(p)] * patch_theta_[p];
  // f_a = -V_e pbar_e R_e g_a.
  for (int t = 0; t < num_tets; ++t) {
    const TetElement& e = elements[size_t(t)];
    const auto& pt = element_patch_[size_t(t)];
    const double pbar = 0.25 * (patch_pressure_[pt[0]] + patch_pressure_[pt[1]] + patch_pressure_[pt[2]] + patch_pressure_[pt[3]]);
    const Eigen::Matrix3d& R = rotations[size_t(t)];
    for (int a = 0; a < 4; ++a)
      force_N.segment<3>(3 * mesh.tets[size_t(t)][size_t(a)]) -=
          e.volume_m3 * pbar * (R * e.shape_gradients.row(a).transpose());
  }
  if (!sink) return;
  // K = sum_P V_P kappa_P b_P b_P^T, b_P[node] = sum_{e in P} V_e / (4 V_P) R_e g_{e,node}:
  // most of this term's time. Patches of different slabs write different rows, so the
  // threads write straight into the matrix: no per-thread copies of the 2-ring matrix to
  // clear and sum (tens of MB a step), three barriers.
  const int threads = num_tets < kParallelMinTets ? 1 : omp_get_max_threads();
  if (threads == 1) {
    if (thread_b_.empty()) thread_b_.assign(1, std::vector<Eigen::Vector3d>(widest_patch_));
    for (int p = 0; p < num_patches(); ++p) AddPatchJacobian(p, damping, sink, thread_b_[0]);
  } else {
    if (partition_.threads != threads) {
      partition_ = PartitionBySlabs(mesh.rest_positions_m, threads, num_patches(), [&](int p, std::vector<int>& nodes) {
        nodes.insert(nodes.end(), patch_nodes_.begin() + node_offsets_[size_t(p)],
                     patch_nodes_.begin() + node_offsets_[size_t(p) + 1]);
      });
      thread_b_.assign(size_t(threads), std::vector<Eigen::Vector3d>(widest_patch_));
    }
    ForEachBySlabs(partition_, [&](int p, int tid) { AddPatchJacobian(p, damping, sink, thread_b_[size_t(tid)]); });
  }
  double* values = sink->matrix->values();
  if (elastic_.corotational_tangent() != CorotationalTangent::kConsistent || definite_ || element_slots_.empty()) return;
  // Consistent tangent: -V pbar R g_a turns with R too. For an isotropic stress pbar that is
  // the twist stiffness V 2 pbar / (s_i + s_j) of each principal plane (the elastic term's
  // formula with sigma_i = pbar); pbar's own derivative is the patch part above.
  TwistVectors twist;
  std::array<double, 3> sign;
  for (int t = 0; t < num_tets; ++t) {
    const Tet& n = mesh.tets[size_t(t)];
    const TetElement& e = elements[size_t(t)];
    const Eigen::Matrix3d F = DeformationGradient(e, state.x_m.segment<3>(3 * n[0]), state.x_m.segment<3>(3 * n[1]),
                                                  state.x_m.segment<3>(3 * n[2]), state.x_m.segment<3>(3 * n[3]));
    if (F.determinant() <= 0) continue;  // inverted: the warped stiffness, as the elastic term
    const auto& pt = element_patch_[size_t(t)];
    const double pbar = 0.25 * (patch_pressure_[pt[0]] + patch_pressure_[pt[1]] + patch_pressure_[pt[2]] + patch_pressure_[pt[3]]);
    const int twists = CorotationalTwistTerms(e, rotations[size_t(t)], F, false, pbar, twist, sign);
    for (int k = 0; k < twists; ++k)
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          const Eigen::Matrix3d K = sign[size_t(k)] * twist[size_t(k)][size_t(a)] * twist[size_t(k)][size_t(b)].transpose();
          sink->AddTo(values, sink->stiffness_times_velocity, element_slots_[size_t(t)][size_t(4 * a + b)], n[size_t(a)], n[size_t(b)], K);
        }
  }
}

double NodalPressureTetForce::PotentialEnergy(const SystemState& state) const {
  const TetMesh& mesh = elastic_.mesh();
  const auto& elements = elastic_.elements();
  Eigen::VectorXd element_theta(mesh.num_tets()), patch_theta;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const Tet& n = mesh.tets[size_t(t)];
    const Eigen::Matrix3d F = DeformationGradient(elements[size_t(t)], state.x_m.segment<3>(3 * n[0]),
                                                  state.x_m.segment<3>(3 * n[1]), state.x_m.segment<3>(3 * n[2]),
                                                  state.x_m.segment<3>(3 * n[3]));
    element_theta[t] = ElementVolumetricStrain(F, elastic_.rotations()[size_t(t)]);
  }
  PatchStrains(element_theta, patch_theta);
  double energy = 0;
  for (int p = 0; p < num_patches(); ++p)
    energy += 0.5 * patch_volume_[size_t(p)] * patch_bulk_[size_t(p)] * patch_theta[p] * patch_theta[p];
  return energy;
}

}  // namespace sedbridge::fem
