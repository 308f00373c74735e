#include "fem/strain_energy_density.h"

#include <omp.h>

#include <algorithm>
#include <map>
#include <set>
#include <stdexcept>

#include "common/hot_clones.h"
#include "fem/rotation_extraction.h"
#include "fem/rotation_step4.h"
#include "fem/tet_sed.h"

namespace sedbridge::fem {

// The Merkel layer's elements with their rotations take 2.7 ms a step on B_fine (one
// thread, 2026-11-25): a parallel region pays from about a thousand elements (1.5 ms on 2
// threads, docs/performance.md "Triangular solves on two cores").
constexpr size_t kParallelMinElements = 1000;

// The SED is stationary in R at the polar rotation: with G = R^T F = S there, turning R by
// a small skew W moves eps by -(W S - S W)/2, and sigma (a polynomial in S) commutes with S,
// so sigma : d eps = 0. A rotation off by d rad moves the SED by ~ mu d^2, so the
// iteration stops after a Newton step below 1e-3 rad (d ~ 1e-6 rad, ~1e-8 Pa) instead of
// confirming 1e-12 rad: one polar step per element a step instead of two.
constexpr double kSedLastNewtonStep_rad = 1e-3;

namespace {

using rotation_step4::Doubles4;
using rotation_step4::Mask4;

// The SED of four elements at a time (G = R^T F corotational, F linear), with the four
// elements' mu and lambda [Pa] (fem/tet_sed.h).
inline __attribute__((always_inline)) void SmallStrainSed4(const Doubles4 (&G)[3][3], const double* mu,
                                                          const double* lambda, Doubles4& sed) {
  Doubles4 mu4, lambda4;
  rotation_step4::Load4(mu4, mu), rotation_step4::Load4(lambda4, lambda);
  StretchSed<Doubles4>(G, mu4, lambda4, sed);
}

// Corotational SED of elements [begin, end) of a SedArrays layout (`count` entries), four at
// a time in vector registers: F from x, warm Newton steps of the rotation from the
// quaternions (x y z w, four per element, updated; rotation_step4::NewtonSteps), sigma:eps/2.
// Elements the steps do not settle (and the last (end - begin) % 4) get status 1 and no
// SED, for ExtractRotation.
SEDBRIDGE_HOT_CLONES
void CorotationalSedBy4(int begin, int end, int count, const int* offset, const double* rest_inverse,
                        const double* mu, const double* lambda, const double* x, double* quaternion,
                        double last_step_rad, double* sed, double* status) {
  using V = Doubles4;
  using rotation_step4::Store4;
  const int vector_end = begin + (end - begin) / 4 * 4;
  for (int k = vector_end; k < end; ++k) status[k] = 1.0;
  const V zero = {0, 0, 0, 0}, one = {1, 1, 1, 1};
  for (int k = begin; k < vector_end; k += 4) {
    V W[3][3], F[3][3], R[3][3], qx, qy, qz, qw;
    rotation_step4::DeformationGradients(k, count, offset, rest_inverse, x, W, F);
    double* q = quaternion + 4 * k;
    rotation_step4::LoadQuaternions(q, qx, qy, qz, qw);
    Mask4 done;
    rotation_step4::NewtonSteps(F, qx, qy, qz, qw, last_step_rad, rotation_step4::kMaxRotationSteps, R, done);
    rotation_step4::StoreQuaternions(q, qx, qy, qz, qw);
    V G[3][3];  // R^T F
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) G[i][j] = R[0][i] * F[0][j] + R[1][i] * F[1][j] + R[2][i] * F[2][j];
    V sed4;
    SmallStrainSed4(G, mu + k, lambda + k, sed4);
    Store4(sed + k, sed4);
    Store4(status + k, done ? zero : one);
  }
}

// Linear SED (ElementSed with R = I) of elements [begin, begin + 4 floor((end - begin) / 4))
// of a SedArrays layout, four at a time; returns where the vector part ends (the caller
// takes the rest). A scalar ElementSed a tet took 190 ns on B's Merkel layer (0.38 ms of
// the pressure-map bridge's 0.58 ms scan; docs/lab-notes/2026-11-28-fe-step-speed-later-runs.md,
// "the linear Merkel SED in vector registers").
SEDBRIDGE_HOT_CLONES
int LinearSedBy4(int begin, int end, int count, const int* offset, const double* rest_inverse, const double* mu,
                 const double* lambda, const double* x, double* sed) {
  using V = Doubles4;
  using rotation_step4::Store4;
  const int vector_end = begin + (end - begin) / 4 * 4;
  for (int k = begin; k < vector_end; k += 4) {
    V W[3][3], F[3][3];
    rotation_step4::DeformationGradients(k, count, offset, rest_inverse, x, W, F);
    V sed4;
    SmallStrainSed4(F, mu + k, lambda + k, sed4);
    Store4(sed + k, sed4);
  }
  return vector_end;
}

}  // namespace

double ElementSed(const TetElement& e, const Eigen::Matrix3d& F, const Eigen::Matrix3d& R) {
  const Eigen::Matrix3d G = R.transpose() * F;
  const double g[3][3] = {{G(0, 0), G(0, 1), G(0, 2)}, {G(1, 0), G(1, 1), G(1, 2)}, {G(2, 0), G(2, 1), G(2, 2)}};
  double sed_Pa = 0;
  StretchSed<double>(g, e.mu_Pa, e.lambda_Pa, sed_Pa);
  return sed_Pa;
}

VertexSedEvaluator::VertexSedEvaluator(const ElasticTetForce& elastic, std::vector<int> vertices,
                                       const NodalPressureTetForce* nodal, const std::vector<char>* averaged)
    : elastic_(elastic), vertices_(std::move(vertices)), nodal_(nodal) {
  if (averaged && averaged->size() != size_t(elastic.mesh().num_tets()))
    throw std::invalid_argument("VertexSedEvaluator: the averaged-element mask needs one entry per tet");
  // Without the nodal term a deviatoric-only element would report SED without its bulk part.
  if (elastic.deviatoric_only() && !nodal)
    throw std::invalid_argument("VertexSedEvaluator: a deviatoric-only elastic term needs its nodal pressure term");
  const TetMesh& mesh = elastic.mesh();
  std::vector<std::vector<int>> node_elements(size_t(mesh.num_nodes()));
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int n : mesh.tets[size_t(t)]) node_elements[size_t(n)].push_back(t);
  std::map<int, int> local;
  for (int v : vertices_)
    for (int t : node_elements.at(size_t(v))) local.emplace(t, 0);
  std::set<int> nodes;
  for (auto& [t, k] : local) {
    k = int(elements_.size());
    elements_.push_back(t);
    for (int n : mesh.tets[size_t(t)]) nodes.insert(n);
  }
  element_nodes_.assign(nodes.begin(), nodes.end());
  for (int v : vertices_) {
    std::vector<int> ids;
    for (int t : node_elements[size_t(v)])
      if (!averaged || (*averaged)[size_t(t)]) ids.push_back(local[t]);
    if (ids.empty())
      for (int t : node_elements[size_t(v)]) ids.push_back(local[t]);
    vertex_local_.push_back(std::move(ids));
  }
  warm_.assign(elements_.size(), Eigen::Quaterniond::Identity());
  element_sed_ = Eigen::VectorXd::Zero(Eigen::Index(elements_.size()));
  if (nodal_) {
    ring_local_.assign(size_t(mesh.num_tets()), -1);
    patch_local_.assign(size_t(nodal_->num_patches()), -1);
    auto add_element = [&](int t) {
      if (ring_local_[size_t(t)] < 0) {
        ring_local_[size_t(t)] = int(ring_.size());
        ring_.push_back(t);
      }
    };
    for (int t : elements_) add_element(t);
    for (int t : elements_)
      for (int a = 0; a < 4; ++a) {
        const int p = nodal_->patch_of(t, a);
        if (patch_local_[size_t(p)] >= 0) continue;
        patch_local_[size_t(p)] = int(patches_.size());
        patches_.push_back(p);
        for (int k = nodal_->patch_offsets()[size_t(p)]; k < nodal_->patch_offsets()[size_t(p) + 1]; ++k)
          add_element(nodal_->patch_elements()[size_t(k)]);
      }
    ring_warm_.assign(ring_.size(), Eigen::Quaterniond::Identity());
    ring_theta_.setZero(Eigen::Index(ring_.size()));
    patch_theta_.setZero(Eigen::Index(patches_.size()));
    ring_F_.resize(ring_.size());
    ring_R_.resize(ring_.size());
  }
}

void VertexSedEvaluator::Evaluate(const Eigen::VectorXd& x, Eigen::VectorXd& vertex_sed) {
  const TetMesh& mesh = elastic_.mesh();
  const bool corotational = elastic_.formulation() == ElasticFormulation::kCorotational;
  if (nodal_) {
    EvaluateNodalPressure(x);
    AverageToVertices(element_sed_, vertex_sed);
    return;
  }
  const int count = int(elements_.size());
  auto element_of = [&](int k) -> const TetElement& { return elastic_.elements()[size_t(elements_[size_t(k)])]; };
  auto gradient_of = [&](int k) {
    const Tet& n = mesh.tets[size_t(elements_[size_t(k)])];
    return DeformationGradient(element_of(k), x.segment<3>(3 * n[0]), x.segment<3>(3 * n[1]), x.segment<3>(3 * n[2]),
                               x.segment<3>(3 * n[3]));
  };
  if (count == 0) {
    AverageToVertices(element_sed_, vertex_sed);
    return;
  }
  if (arrays_.mu.size() != size_t(count)) {
    arrays_.offset.resize(4 * size_t(count));
    arrays_.rest_inverse.resize(9 * size_t(count));
    arrays_.mu.resize(size_t(count));
    arrays_.lambda.resize(size_t(count));
    arrays_.status.assign(size_t(count), 0.0);
    for (int k = 0; k < count; ++k) {
      const TetElement& e = element_of(k);
      for (int a = 0; a < 4; ++a) arrays_.offset[size_t(a * count + k)] = 3 * mesh.tets[size_t(elements_[size_t(k)])][size_t(a)];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) arrays_.rest_inverse[size_t((3 * i + j) * count + k)] = e.rest_inverse(i, j);
      arrays_.mu[size_t(k)] = e.mu_Pa;
      arrays_.lambda[size_t(k)] = e.lambda_Pa;
    }
  }
  if (!corotational) {
#pragma omp parallel if (elements_.size() > kParallelMinElements)
    {
      const int threads = omp_get_num_threads(), tid = omp_get_thread_num();
      const int begin = int(long(count) * tid / threads), end = int(long(count) * (tid + 1) / threads);
      const int vector_end = LinearSedBy4(begin, end, count, arrays_.offset.data(), arrays_.rest_inverse.data(),
                                          arrays_.mu.data(), arrays_.lambda.data(), x.data(), element_sed_.data());
      for (int k = vector_end; k < end; ++k)
        element_sed_[k] = ElementSed(element_of(k), gradient_of(k), Eigen::Matrix3d::Identity());
    }
    AverageToVertices(element_sed_, vertex_sed);
    return;
  }
  static_assert(sizeof(Eigen::Quaterniond) == 4 * sizeof(double), "quaternions are read as x y z w, four apart");
  // The SED four elements at a time on each thread's share (F, warm polar steps,
  // sigma:eps/2 in vector registers); ExtractRotation where the steps do not settle.
#pragma omp parallel if (elements_.size() > kParallelMinElements)
  {
    const int threads = omp_get_num_threads(), tid = omp_get_thread_num();
    const int begin = int(long(count) * tid / threads), end = int(long(count) * (tid + 1) / threads);
    CorotationalSedBy4(begin, end, count, arrays_.offset.data(), arrays_.rest_inverse.data(), arrays_.mu.data(),
                       arrays_.lambda.data(), x.data(), warm_[0].coeffs().data(), kSedLastNewtonStep_rad,
                       element_sed_.data(), arrays_.status.data());
    for (int k = begin; k < end; ++k)
      if (arrays_.status[size_t(k)] != 0) {
        const Eigen::Matrix3d F = gradient_of(k);
        element_sed_[k] = ElementSed(element_of(k), F, ExtractRotation(F, warm_[size_t(k)], 20, kSedLastNewtonStep_rad));
      }
  }
  AverageToVertices(element_sed_, vertex_sed);
}

void VertexSedEvaluator::EvaluateNodalPressure(const Eigen::VectorXd& x) {
  const TetMesh& mesh = elastic_.mesh();
  const bool corotational = elastic_.formulation() == ElasticFormulation::kCorotational;
  // Rotations and volumetric strains of the ring (each element once), then the patch
  // strains, then sigma:eps/2 of elements_ with the smoothed volumetric strain.
#pragma omp parallel for schedule(static) if (ring_.size() > kParallelMinElements)
  for (int k = 0; k < int(ring_.size()); ++k) {
    const int t = ring_[size_t(k)];
    const Tet& n = mesh.tets[size_t(t)];
    const TetElement& e = elastic_.elements()[size_t(t)];
    ring_F_[size_t(k)] = DeformationGradient(e, x.segment<3>(3 * n[0]), x.segment<3>(3 * n[1]), x.segment<3>(3 * n[2]),
                                             x.segment<3>(3 * n[3]));
    // Elements whose SED is wanted get a fresh rotation. The others only feed tr(R^T F): at
    // the polar R its derivative in R vanishes (trace of skew times symmetric), so the
    // elastic term's rotation from the last assembly is exact to second order, and saves
    // a polar decomposition for each of the ~3x more ring elements.
    if (!corotational)
      ring_R_[size_t(k)].setIdentity();
    else if (k < int(elements_.size()))
      ring_R_[size_t(k)] = ExtractRotation(ring_F_[size_t(k)], ring_warm_[size_t(k)], 20, kSedLastNewtonStep_rad);
    else
      ring_R_[size_t(k)] = elastic_.rotations()[size_t(t)];
    ring_theta_[k] = NodalPressureTetForce::ElementVolumetricStrain(ring_F_[size_t(k)], ring_R_[size_t(k)]);
  }
  const auto& offsets = nodal_->patch_offsets();
  const auto& members = nodal_->patch_elements();
  for (size_t q = 0; q < patches_.size(); ++q) {
    const int p = patches_[q];
    double sum = 0;
    for (int k = offsets[size_t(p)]; k < offsets[size_t(p) + 1]; ++k) {
      const int t = members[size_t(k)];
      sum += elastic_.elements()[size_t(t)].volume_m3 * ring_theta_[ring_local_[size_t(t)]];
    }
    patch_theta_[Eigen::Index(q)] = sum / (4.0 * nodal_->patch_volume_m3()[size_t(p)]);
  }
  for (size_t k = 0; k < elements_.size(); ++k) {
    const int t = elements_[k];  // ring_[k] == t: elements_ come first in the ring
    double thetabar = 0;
    for (int a = 0; a < 4; ++a) thetabar += 0.25 * patch_theta_[patch_local_[size_t(nodal_->patch_of(t, a))]];
    const double kappa = nodal_->patch_bulk_Pa()[size_t(nodal_->patch_of(t, 0))];
    element_sed_[Eigen::Index(k)] =
        ElementSed(elastic_.elements()[size_t(t)], ring_F_[k], ring_R_[k]) + 0.5 * kappa * thetabar * thetabar;
  }
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
