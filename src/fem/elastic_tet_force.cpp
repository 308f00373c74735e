#include "fem/elastic_tet_force.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <omp.h>
#include <stdexcept>

#include "common/hot_clones.h"
#include "fem/rotation_extraction.h"
#include "fem/rotation_step4.h"

namespace sedbridge::fem {
namespace {
// An element's rotation off by d rad turns its force by ~d (relative; R is the force's
// prefactor, and the strain in the rotated frame moves by d times the strain only). Newton
// leaves ~theta^2 after a step of theta (rotation_extraction.h), so stopping after a step
// below 1e-4 rad leaves ~1e-8: under the linear solves' own tolerances, and in a dynamic
// step (rotations change by ~1e-5 rad a millisecond) one polar step an element instead of
// a second that only confirms it.
constexpr double kElementLastNewtonStep_rad = 1e-4;
// The node rotations only warp the preconditioner's rest factor: 1e-3 rad (~1e-6 left).
constexpr double kNodeLastNewtonStep_rad = 1e-3;

// Tets below which the linear path's inversion check runs on one thread [elements]: the check
// is a few flops a tet, so forking a team costs more than it saves until the mesh is large.
constexpr size_t kParallelInversionCheckMinTets = 100000;
// Tets below which assembly runs on one thread [elements]: below this the per-thread
// partial sums and their reduction cost more than the element work they split.
constexpr size_t kParallelAssemblyMinTets = 256;
// The preconditioner's node rotations: one thread takes ~0.1 ms on B's 1793 nodes.
constexpr int kParallelNodeRotationsMinNodes = 1000;
// Parallel assembly by slabs instead of per-thread partial sums when the matrix has this
// many times the values of the elements' own blocks (see AddForce).
constexpr double kSlabsAbovePatternRatio = 1.5;
// Twist stiffness (sigma_i + sigma_j) / (s_i + s_j) is only used where the element is not
// near inversion in that plane (s_i + s_j above this) [-]: near 0 the quotient is
// ill-conditioned, and the warped stiffness is the safe choice there.
constexpr double kMinTwistStretchSum = 0.5;

// y = scale R K0 R^T v for elements [begin, end), structure of arrays with `count`
// entries each (so the loop vectorizes across elements): element e's node a at
// v + offset[a * count + e] (3 * node), rotation entry (i, j) at rotation[(3 i + j) * count + e],
// Dm^-1 entry (i, j) at rest_inverse[(3 i + j) * count + e], V mu and V lambda per element;
// node a's three components out at y[(3 a + k) * count + e]. In stress form: L = R^T dv Dm^-1,
// sigma = mu (L + L^T) + lambda tr(L) I, nodes 1-3 get V R sigma Dm^-T, node 0 minus their
// sum (the shape gradients sum to zero).
SEDBRIDGE_HOT_CLONES
void ElementStiffnessTimes(int begin, int end, int count, const int* offset, const double* rotation, const double* rest_inverse,
                           const double* mu_volume, const double* lambda_volume, double scale, const double* v,
                           double* y) {
#pragma omp simd
  for (int e = begin; e < end; ++e) {
    double R[3][3], W[3][3], dv[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        R[i][j] = rotation[(3 * i + j) * count + e];
        W[i][j] = rest_inverse[(3 * i + j) * count + e];
      }
    const double* v0 = v + offset[e];
    for (int c = 0; c < 3; ++c) {
      const double* vc = v + offset[(c + 1) * count + e];
      for (int k = 0; k < 3; ++k) dv[k][c] = vc[k] - v0[k];
    }
    double T[3][3], L[3][3], P[3][3];
    for (int i = 0; i < 3; ++i)  // T = R^T dv
      for (int j = 0; j < 3; ++j) T[i][j] = R[0][i] * dv[0][j] + R[1][i] * dv[1][j] + R[2][i] * dv[2][j];
    for (int i = 0; i < 3; ++i)  // L = T W
      for (int j = 0; j < 3; ++j) L[i][j] = T[i][0] * W[0][j] + T[i][1] * W[1][j] + T[i][2] * W[2][j];
    const double mu = scale * mu_volume[e], lambda_tr = scale * lambda_volume[e] * (L[0][0] + L[1][1] + L[2][2]);
    double S[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) S[i][j] = mu * (L[i][j] + L[j][i]) + (i == j ? lambda_tr : 0.0);
    for (int i = 0; i < 3; ++i)  // P = R S
      for (int j = 0; j < 3; ++j) P[i][j] = R[i][0] * S[0][j] + R[i][1] * S[1][j] + R[i][2] * S[2][j];
    for (int k = 0; k < 3; ++k) {
      double sum = 0;
      for (int a = 1; a < 4; ++a) {  // node a: P times row a-1 of Dm^-1 (its shape gradient)
        const double ya = P[k][0] * W[a - 1][0] + P[k][1] * W[a - 1][1] + P[k][2] * W[a - 1][2];
        y[(3 * a + k) * count + e] = ya;
        sum += ya;
      }
      y[k * count + e] = -sum;
    }
  }
}

// The corotational force of elements [begin, end) with warm-started Newton steps of their
// rotations (rotation_step4::NewtonSteps), four elements at a time in vector registers (arrays as
// ElementStiffnessTimes; positions x, velocities v (kDamping), quaternions as Eigen stores
// them, x y z w, four per element). ExtractRotation's step and stop, written out: an
// element whose last Newton step is safe and below last_step_rad (the error left is its
// square) is done, with its new quaternion and rotation (rotation[(3 i + j) * count + e]) and node
// a's force component k at minus_force[(3 a + k) * count + e] (f = -V R sigma(eps) g_a,
// eps = sym(R^T F) - I plus beta sym(R^T dv Dm^-1)); status[e] = 0. Any other (a step
// too long or unsafe, a quaternion off unit length, NaN, and the last (end - begin) % 4
// elements) gets status 1, its quaternion where the steps left it, for ExtractRotation.
// inverted[e] = 1 where det F <= 0. (Explicit vectors: GCC did not vectorize this loop
// written for one element, its selections turned into branches.)
// (Vectors pass by reference only, fem/rotation_step4.h.)
using rotation_step4::Doubles4;
using rotation_step4::Mask4;

template <bool kDamping>
inline __attribute__((always_inline)) void CorotationalForcesBody(
    int begin, int end, int count, const int* offset, const double* rest_inverse, const double* mu_volume,
    const double* lambda_volume, double beta, double last_step_rad, const double* x, const double* v,
    double* quaternion, double* rotation, double* minus_force, double* status, double* inverted) {
  using V = Doubles4;
  using rotation_step4::Load4;
  using rotation_step4::Store4;
  const int vector_end = begin + (end - begin) / 4 * 4;
  for (int e = vector_end; e < end; ++e) status[e] = 1.0, inverted[e] = 0.0;  // ExtractRotation's
  const V zero = {0, 0, 0, 0}, one = {1, 1, 1, 1};
  for (int e = begin; e < vector_end; e += 4) {
    V W[3][3], F[3][3];
    rotation_step4::DeformationGradients(e, count, offset, rest_inverse, x, W, F);
    const V det = F[0][0] * (F[1][1] * F[2][2] - F[1][2] * F[2][1]) - F[0][1] * (F[1][0] * F[2][2] - F[1][2] * F[2][0]) +
                  F[0][2] * (F[1][0] * F[2][1] - F[1][1] * F[2][0]);
    Store4(inverted + e, det <= zero ? one : zero);
    double* q = quaternion + 4 * e;
    V qx, qy, qz, qw, R[3][3];
    rotation_step4::LoadQuaternions(q, qx, qy, qz, qw);
    Mask4 done;
    rotation_step4::NewtonSteps(F, qx, qy, qz, qw, last_step_rad, rotation_step4::kMaxRotationSteps, R, done);
    Store4(status + e, done ? zero : one);
    rotation_step4::StoreQuaternions(q, qx, qy, qz, qw);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) Store4(rotation + (3 * i + j) * count + e, R[i][j]);
    V L[3][3];  // R^T F - I (+ beta R^T dv Dm^-1)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) L[i][j] = R[0][i] * F[0][j] + R[1][i] * F[1][j] + R[2][i] * F[2][j];
    for (int i = 0; i < 3; ++i) L[i][i] -= 1.0;
    if (kDamping) {
      V d[3][3], T[3][3];
      rotation_step4::EdgeVectors(e, count, offset, v, d);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) T[i][j] = R[0][i] * d[0][j] + R[1][i] * d[1][j] + R[2][i] * d[2][j];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) L[i][j] += beta * (T[i][0] * W[0][j] + T[i][1] * W[1][j] + T[i][2] * W[2][j]);
    }
    V mu, lambda_volume_e;
    Load4(mu, mu_volume + e), Load4(lambda_volume_e, lambda_volume + e);
    const V lambda_tr = lambda_volume_e * (L[0][0] + L[1][1] + L[2][2]);
    V S[3][3], P[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) S[i][j] = mu * (L[i][j] + L[j][i]) + (i == j ? lambda_tr : zero);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) P[i][j] = R[i][0] * S[0][j] + R[i][1] * S[1][j] + R[i][2] * S[2][j];
    for (int k = 0; k < 3; ++k) {
      V sum = zero;
      for (int a = 1; a < 4; ++a) {
        const V ya = P[k][0] * W[a - 1][0] + P[k][1] * W[a - 1][1] + P[k][2] * W[a - 1][2];
        Store4(minus_force + (3 * a + k) * count + e, ya);
        sum += ya;
      }
      Store4(minus_force + k * count + e, -sum);
    }
  }
}

SEDBRIDGE_HOT_CLONES
void CorotationalForcesDamped(int begin, int end, int count, const int* offset, const double* rest_inverse,
                              const double* mu_volume, const double* lambda_volume, double beta, double last_step_rad,
                              const double* x, const double* v, double* quaternion, double* rotation,
                              double* minus_force, double* status, double* inverted) {
  CorotationalForcesBody<true>(begin, end, count, offset, rest_inverse, mu_volume, lambda_volume, beta, last_step_rad,
                               x, v, quaternion, rotation, minus_force, status, inverted);
}

SEDBRIDGE_HOT_CLONES
void CorotationalForcesUndamped(int begin, int end, int count, const int* offset, const double* rest_inverse,
                                const double* mu_volume, const double* lambda_volume, double last_step_rad,
                                const double* x, double* quaternion, double* rotation, double* minus_force,
                                double* status, double* inverted) {
  CorotationalForcesBody<false>(begin, end, count, offset, rest_inverse, mu_volume, lambda_volume, 0.0, last_step_rad,
                                x, nullptr, quaternion, rotation, minus_force, status, inverted);
}

}  // namespace

int CorotationalTwistTerms(const TetElement& e, const Eigen::Matrix3d& R, const Eigen::Matrix3d& F,
                           bool with_element_stress, double pressure_Pa, TwistVectors& t, std::array<double, 3>& sign) {
  Eigen::Matrix3d A = R.transpose() * F;
  const Eigen::Matrix3d S = 0.5 * (A + A.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(S);
  const Eigen::Vector3d s = eig.eigenvalues();
  const Eigen::Matrix3d V = eig.eigenvectors();
  const Eigen::Matrix3d U = R * V;
  const double tr_eps = s.sum() - 3.0;
  Eigen::Vector3d sigma = Eigen::Vector3d::Constant(pressure_Pa);
  if (with_element_stress)
    sigma += (2.0 * e.mu_Pa) * (s.array() - 1.0).matrix() + Eigen::Vector3d::Constant(e.lambda_Pa * tr_eps);
  Eigen::Vector3d g_local[4];  // shape gradients in the principal frame
  for (int a = 0; a < 4; ++a) g_local[a] = V.transpose() * e.shape_gradients.row(a).transpose();
  static constexpr int kPlanes[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  int n = 0;
  for (const auto& plane : kPlanes) {
    const int i = plane[0], j = plane[1];
    const double stretch_sum = s[i] + s[j];
    if (!(stretch_sum > kMinTwistStretchSum)) continue;
    const double k = (sigma[i] + sigma[j]) / stretch_sum;
    if (k == 0) continue;
    // Twist mode dF = U (e_i e_j^T - e_j e_i^T) V^T / sqrt(2); node a's entry is dF g_a.
    const double scale = std::sqrt(0.5 * std::abs(k) * e.volume_m3);
    sign[size_t(n)] = k < 0 ? -1.0 : 1.0;
    for (int a = 0; a < 4; ++a) t[size_t(n)][size_t(a)] = scale * (U.col(i) * g_local[a][j] - U.col(j) * g_local[a][i]);
    ++n;
  }
  return n;
}

ElasticTetForce::ElasticTetForce(const TetMesh& mesh, ElasticFormulation formulation,
                                 double rayleigh_beta_s, bool deviatoric_only)
    : mesh_(mesh), formulation_(formulation), beta_s_(rayleigh_beta_s), deviatoric_only_(deviatoric_only) {
  elements_ = PrecomputeElements(mesh);
  // lambda -> -2 mu / 3 turns sigma = 2 mu eps + lambda tr(eps) I into 2 mu dev(eps): the
  // kernels below stay as they are and the bulk part is left to the nodal pressure term.
  if (deviatoric_only_)
    for (TetElement& e : elements_) e.lambda_Pa = -2.0 * e.mu_Pa / 3.0;
  quaternions_.assign(elements_.size(), Eigen::Quaterniond::Identity());
  rotations_.assign(elements_.size(), Eigen::Matrix3d::Identity());
  node_elements_.resize(size_t(mesh.num_nodes()));
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int n : mesh.tets[size_t(t)]) node_elements_[size_t(n)].push_back(t);
  rest_positions_.resize(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) rest_positions_.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  if (formulation_ == ElasticFormulation::kLinear) {
    std::vector<std::pair<int, int>> pairs;
    AppendCoupledNodes(pairs);
    rest_stiffness_.Build(mesh.num_nodes(), pairs);
    for (size_t t = 0; t < elements_.size(); ++t) {
      const TetElement& e = elements_[t];
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          const Eigen::Vector3d ga = e.shape_gradients.row(a).transpose(), gb = e.shape_gradients.row(b).transpose();
          rest_stiffness_.AddBlock(rest_stiffness_.Slot(mesh.tets[t][size_t(a)], mesh.tets[t][size_t(b)]),
                                   StiffnessBlock(e, ga, gb, ga.dot(gb)));
        }
    }
  }
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
  std::vector<char> used(size_t(matrix.num_values()) / 9 + 1, 0);
  own_values_ = 0;
  for (size_t t = 0; t < elements_.size(); ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        const int slot = matrix.Slot(mesh_.tets[t][size_t(a)], mesh_.tets[t][size_t(b)]);
        slots_[t][size_t(4 * a + b)] = slot;
        if (!used[size_t(slot)]) used[size_t(slot)] = 1, own_values_ += 9;
      }
}

void ElasticTetForce::AddForce(const SystemState& state, Eigen::VectorXd& force_N, JacobianSink* sink) {
  if (sink && slots_.empty()) throw std::logic_error("ElasticTetForce: BindMatrix not called");
  const bool corotational = formulation_ == ElasticFormulation::kCorotational;
  const bool damping = state.dynamic && beta_s_ > 0;
  last_dynamic_ = state.dynamic;
  product_.rotations_current = false;

  if (!corotational) {
    // f = -K0 (x - X) - beta K0 v
    work_ = state.x_m - rest_positions_;
    if (damping) work_ += beta_s_ * state.v_m_s;
    rest_stiffness_.Multiply(work_, k_times_work_);
    force_N -= k_times_work_;
    int inverted = 0;
#pragma omp parallel for schedule(static) reduction(+ : inverted) if (elements_.size() > kParallelInversionCheckMinTets)
    for (int t = 0; t < int(elements_.size()); ++t) {
      const Tet& n = mesh_.tets[size_t(t)];
      if (SignedVolume(state.x_m.segment<3>(3 * n[0]), state.x_m.segment<3>(3 * n[1]), state.x_m.segment<3>(3 * n[2]),
                       state.x_m.segment<3>(3 * n[3])) <= 0)
        ++inverted;
    }
    inverted_elements_ = inverted;
    if (!sink) return;
  }

  // Two ways to run in parallel. With one partial sum per thread and a single reduction:
  // two synchronisation points a step instead of one per element colour, which matters on a
  // loaded 2-core machine where every barrier can cost a scheduler time slice; but every
  // thread clears and sums a copy of the whole matrix. By slabs (fem/slab_partition.h):
  // elements of different slabs write different rows, straight into the matrix, and the
  // slab boundaries' elements run after a barrier. When other terms widen the pattern well
  // beyond the elements' own blocks (the nodal-pressure term's 2-ring: about 3x), the copies
  // cost more than the boundaries: slabs. Measured on B:
  // docs/lab-notes/2026-11-27-validation-runs.md#nodal-pressure-tet ("the nodal-pressure term on two threads").
  if (corotational && !sink) {  // the force alone (matrix-free steps): vectorized
    inverted_elements_ = AddCorotationalForceVectorized(state, force_N);
    return;
  }
  const bool force = corotational;
  const int threads = omp_get_max_threads();
  int inverted = 0;
  if (threads == 1 || elements_.size() < kParallelAssemblyMinTets) {
    for (int t = 0; t < int(elements_.size()); ++t)
      inverted += AccumulateElement(t, state, force, force_N, sink, sink ? sink->matrix->values() : nullptr,
                                    sink ? sink->stiffness_times_velocity : nullptr);
  } else if (sink && sink->matrix->num_values() > kSlabsAbovePatternRatio * own_values_) {
    if (partition_.threads != threads)
      partition_ = PartitionBySlabs(mesh_.rest_positions_m, threads, int(elements_.size()),
                                    [&](int t, std::vector<int>& nodes) {
                                      for (int n : mesh_.tets[size_t(t)]) nodes.push_back(n);
                                    });
    double* values = sink->matrix->values();
    std::vector<int> counts(size_t(threads), 0);
    ForEachBySlabs(partition_, [&](int t, int tid) {
      // Written only for an inverted element: the counters share a cache line.
      if (const int c = AccumulateElement(t, state, force, force_N, sink, values, sink->stiffness_times_velocity))
        counts[size_t(tid)] += c;
    });
    for (int c : counts) inverted += c;
  } else {
    thread_values_.resize(size_t(threads));
    thread_force_.resize(size_t(threads));
    thread_k_times_v_.resize(size_t(threads));
    const int num_values = sink ? sink->matrix->num_values() : 0;
    const int dofs = int(force_N.size());
#pragma omp parallel reduction(+ : inverted)
    {
      const int tid = omp_get_thread_num();
      double* values = nullptr;
      Eigen::VectorXd* kv = nullptr;
      Eigen::VectorXd* f = &force_N;
      if (tid > 0) {
        thread_force_[size_t(tid)].setZero(dofs);
        f = &thread_force_[size_t(tid)];
        if (sink) {
          thread_values_[size_t(tid)].assign(size_t(num_values), 0.0);
          values = thread_values_[size_t(tid)].data();
          if (sink->velocity) {
            thread_k_times_v_[size_t(tid)].setZero(dofs);
            kv = &thread_k_times_v_[size_t(tid)];
          }
        }
      } else if (sink) {
        values = sink->matrix->values();
        kv = sink->stiffness_times_velocity;
      }
#pragma omp for schedule(static)
      for (int t = 0; t < int(elements_.size()); ++t) inverted += AccumulateElement(t, state, force, *f, sink, values, kv);
      // implicit barrier: all partial sums are complete
      const int active = omp_get_num_threads();
#pragma omp for schedule(static)
      for (int k = 0; k < dofs; ++k)
        for (int p = 1; p < active; ++p) force_N[k] += thread_force_[size_t(p)][k];
      if (sink) {
        double* out = sink->matrix->values();
#pragma omp for schedule(static)
        for (int k = 0; k < num_values; ++k)
          for (int p = 1; p < active; ++p) out[k] += thread_values_[size_t(p)][size_t(k)];
        if (sink->velocity) {
#pragma omp for schedule(static)
          for (int k = 0; k < dofs; ++k)
            for (int p = 1; p < active; ++p) (*sink->stiffness_times_velocity)[k] += thread_k_times_v_[size_t(p)][k];
        }
      }
    }
  }
  if (corotational) inverted_elements_ = inverted;
}

int ElasticTetForce::AccumulateElement(int t, const SystemState& state, bool force, Eigen::VectorXd& force_N,
                                       JacobianSink* sink, double* values, Eigen::VectorXd* k_times_v) {
  const bool corotational = formulation_ == ElasticFormulation::kCorotational;
  const bool damping = state.dynamic && beta_s_ > 0;
  const TetElement& e = elements_[size_t(t)];
  const Tet& n = mesh_.tets[size_t(t)];
  int inverted = 0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d F;
  if (corotational) {
    const Eigen::Vector3d x0 = state.x_m.segment<3>(3 * n[0]);
    F = DeformationGradient(e, x0, state.x_m.segment<3>(3 * n[1]),
                                                  state.x_m.segment<3>(3 * n[2]), state.x_m.segment<3>(3 * n[3]));
    if (F.determinant() <= 0) inverted = 1;
    R = ExtractRotation(F, quaternions_[size_t(t)], 20, kElementLastNewtonStep_rad);
    rotations_[size_t(t)] = R;
    if (force) {
      const Eigen::Matrix3d P = VolumeRotatedStress(t, R, F, state, damping);
      for (int a = 0; a < 4; ++a) force_N.segment<3>(3 * n[size_t(a)]) -= P * e.shape_gradients.row(a).transpose();
    }
  }
  if (!sink) return inverted;
  Eigen::Vector3d h[4];
  for (int a = 0; a < 4; ++a) h[a] = R * e.shape_gradients.row(a).transpose();
  TwistVectors twist;
  std::array<double, 3> twist_sign;
  const int twists =
      corotational && tangent_ == CorotationalTangent::kConsistent && !definite_ && !inverted ? CorotationalTwistTerms(e, R, F, true, 0.0, twist, twist_sign)
                                                                                          : 0;
  // Damping stays the warped stiffness's (D = beta R K0 R^T), the twists are stiffness only:
  // without twists, each block and its damping in one pass over the matrix's values.
  const double damping_scale = damping ? beta_s_ * sink->damping_scale : 0.0;
  for (int a = 0; a < 4; ++a) {
    for (int b = a; b < 4; ++b) {
      Eigen::Matrix3d K = StiffnessBlock(e, h[a], h[b], e.shape_gradients.row(a).dot(e.shape_gradients.row(b)));
      const int ab = slots_[size_t(t)][size_t(4 * a + b)], ba = slots_[size_t(t)][size_t(4 * b + a)];
      double scale = sink->stiffness_scale + damping_scale;
      if (twists > 0) {
        if (damping) {
          sink->matrix->AddBlockTo(values, ab, K, damping_scale);
          if (b != a) sink->matrix->AddBlockTo(values, ba, K.transpose(), damping_scale);
        }
        for (int k = 0; k < twists; ++k)
          K.noalias() += twist_sign[size_t(k)] * twist[size_t(k)][size_t(a)] * twist[size_t(k)][size_t(b)].transpose();
        scale = sink->stiffness_scale;
      }
      sink->matrix->AddBlockTo(values, ab, K, scale);
      if (b != a) sink->matrix->AddBlockTo(values, ba, K.transpose(), scale);
    }
  }
  if (sink->velocity) {
    // K v in stress form, as the force: (K v)_a = V R sigma(sym(R^T dv Dm^-1)) g_a, the
    // strain of the velocity in the element's rotated frame (16 block products otherwise);
    // each twist's rank-one part adds sign t_a (t . v).
    const Eigen::VectorXd& v = *sink->velocity;
    AddElementStiffnessTimes(t, R, 1.0, v, *k_times_v);
    for (int k = 0; k < twists; ++k) {
      double tv = 0;
      for (int b = 0; b < 4; ++b) tv += twist[size_t(k)][size_t(b)].dot(v.segment<3>(3 * n[size_t(b)]));
      for (int a = 0; a < 4; ++a) k_times_v->segment<3>(3 * n[size_t(a)]) += (twist_sign[size_t(k)] * tv) * twist[size_t(k)][size_t(a)];
    }
  }
  return inverted;
}

Eigen::Matrix3d ElasticTetForce::VolumeRotatedStress(int t, const Eigen::Matrix3d& R, const Eigen::Matrix3d& F,
                                                     const SystemState& state, bool damping) const {
  // Stress form of f = -R K0 (R^T x - X): f_a = -V R sigma(eps) g_a with
  // eps = sym(R^T F) - I (the small strain in the element's rotated frame).
  const TetElement& e = elements_[size_t(t)];
  const Tet& n = mesh_.tets[size_t(t)];
  Eigen::Matrix3d G = R.transpose() * F;
  Eigen::Matrix3d eps = 0.5 * (G + G.transpose());
  eps.diagonal().array() -= 1.0;
  if (damping) {
    Eigen::Matrix3d dv;
    const Eigen::Vector3d v0 = state.v_m_s.segment<3>(3 * n[0]);
    dv << state.v_m_s.segment<3>(3 * n[1]) - v0, state.v_m_s.segment<3>(3 * n[2]) - v0,
        state.v_m_s.segment<3>(3 * n[3]) - v0;
    const Eigen::Matrix3d Gd = R.transpose() * dv * e.rest_inverse;
    eps += beta_s_ * 0.5 * (Gd + Gd.transpose());
  }
  Eigen::Matrix3d sigma = (2.0 * e.mu_Pa) * eps;
  sigma.diagonal().array() += e.lambda_Pa * eps.trace();
  return e.volume_m3 * (R * sigma);
}

int ElasticTetForce::AddCorotationalForceVectorized(const SystemState& state, Eigen::VectorXd& force_N) {
  const int count = int(elements_.size());
  if (count == 0) return 0;
  EnsureProductArrays();
  const bool damping = state.dynamic && beta_s_ > 0;
  double* y = product_.element_out.data();
  double* rotation = product_.rotation.data();
  double* status = product_.status.data();
  double* inverted_flag = product_.inverted.data();
  const bool parallel = omp_get_max_threads() > 1 && size_t(count) >= kParallelAssemblyMinTets;
  if (parallel) product_.ReserveTeam(omp_get_max_threads(), int(force_N.size()));
  int inverted = 0, scalar = 0;
#pragma omp parallel if (parallel) reduction(+ : inverted, scalar)
  {
    const int threads = omp_get_num_threads(), tid = omp_get_thread_num();
    const int begin = int(long(count) * tid / threads), end = int(long(count) * (tid + 1) / threads);
    static_assert(sizeof(Eigen::Quaterniond) == 4 * sizeof(double), "quaternions are read as x y z w, four apart");
    double* quaternion = quaternions_[0].coeffs().data();
    if (damping)
      CorotationalForcesDamped(begin, end, count, product_.offset.data(), product_.rest_inverse.data(),
                               product_.mu_volume.data(), product_.lambda_volume.data(), beta_s_,
                               kElementLastNewtonStep_rad, state.x_m.data(), state.v_m_s.data(), quaternion, rotation,
                               y, status, inverted_flag);
    else
      CorotationalForcesUndamped(begin, end, count, product_.offset.data(), product_.rest_inverse.data(),
                                 product_.mu_volume.data(), product_.lambda_volume.data(), kElementLastNewtonStep_rad,
                                 state.x_m.data(), quaternion, rotation, y, status, inverted_flag);
    for (int t = begin; t < end; ++t) {
      inverted += inverted_flag[t] != 0;
      Eigen::Matrix3d& R = rotations_[size_t(t)];
      if (status[t] != 0) {
        ++scalar;  // more Newton steps, or none safe: the scalar iteration
        const TetElement& e = elements_[size_t(t)];
        const Tet& n = mesh_.tets[size_t(t)];
        const Eigen::Matrix3d F = DeformationGradient(e, state.x_m.segment<3>(3 * n[0]), state.x_m.segment<3>(3 * n[1]),
                                                      state.x_m.segment<3>(3 * n[2]), state.x_m.segment<3>(3 * n[3]));
        R = ExtractRotation(F, quaternions_[size_t(t)], 20, kElementLastNewtonStep_rad);
        const Eigen::Matrix3d P = VolumeRotatedStress(t, R, F, state, damping);
        for (int a = 0; a < 4; ++a) {
          const Eigen::Vector3d ya = P * e.shape_gradients.row(a).transpose();
          for (int k = 0; k < 3; ++k) y[(3 * a + k) * count + t] = ya[k];
        }
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) rotation[(3 * i + j) * count + t] = R(i, j);
      } else {
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) R(i, j) = rotation[(3 * i + j) * count + t];
      }
    }
    product_.AddElementSums(y, begin, end, -1.0, force_N);
  }
  product_.rotations_current = true;
  scalar_rotations_ = scalar;
  return inverted;
}

void ElasticTetForce::AddElementStiffnessTimes(int t, const Eigen::Matrix3d& R, double scale, const Eigen::VectorXd& v,
                                               Eigen::VectorXd& out) const {
  const TetElement& e = elements_[size_t(t)];
  const Tet& n = mesh_.tets[size_t(t)];
  const Eigen::Vector3d v0 = v.segment<3>(3 * n[0]);
  Eigen::Matrix3d dv;
  dv << v.segment<3>(3 * n[1]) - v0, v.segment<3>(3 * n[2]) - v0, v.segment<3>(3 * n[3]) - v0;
  const Eigen::Matrix3d L = R.transpose() * dv * e.rest_inverse;
  Eigen::Matrix3d sigma = e.mu_Pa * (L + L.transpose());
  sigma.diagonal().array() += e.lambda_Pa * L.trace();
  const Eigen::Matrix3d P = (scale * e.volume_m3) * (R * sigma);
  for (int a = 0; a < 4; ++a) out.segment<3>(3 * n[size_t(a)]) += P * e.shape_gradients.row(a).transpose();
}

bool ElasticTetForce::AppliesJacobian() const {
  return formulation_ == ElasticFormulation::kLinear || tangent_ == CorotationalTangent::kWarped || definite_;
}

void ElasticTetForce::AddJacobianTimes(double stiffness_scale, double damping_scale, const Eigen::VectorXd& v,
                                       Eigen::VectorXd& out) {
  const double scale = stiffness_scale + (last_dynamic_ && beta_s_ > 0 ? beta_s_ * damping_scale : 0.0);
  if (scale == 0) return;
  if (formulation_ == ElasticFormulation::kLinear) {
    rest_stiffness_.Multiply(v, rest_product_);
    out += scale * rest_product_;
    return;
  }
  // Two passes, each free of write conflicts: every element's nodal products into its own
  // slots (vectorized across elements), then each thread adds its own elements' slots to the
  // nodes (AddElementSums).
  const int count = int(elements_.size());
  EnsureProductArrays();
  if (!product_.rotations_current) {
    for (int t = 0; t < count; ++t)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) product_.rotation[size_t((3 * i + j) * count + t)] = rotations_[size_t(t)](i, j);
    product_.rotations_current = true;
  }
  const bool parallel = omp_get_max_threads() > 1 && size_t(count) >= kParallelAssemblyMinTets;
  if (parallel) product_.ReserveTeam(omp_get_max_threads(), int(out.size()));
  double* y = product_.element_out.data();
#pragma omp parallel if (parallel)
  {
    const int threads = omp_get_num_threads(), tid = omp_get_thread_num();
    const int begin = int(long(count) * tid / threads), end = int(long(count) * (tid + 1) / threads);
    ElementStiffnessTimes(begin, end, count, product_.offset.data(), product_.rotation.data(),
                          product_.rest_inverse.data(), product_.mu_volume.data(), product_.lambda_volume.data(), scale,
                          v.data(), y);
    product_.AddElementSums(y, begin, end, 1.0, out);
  }
}

void ElasticTetForce::EnsureProductArrays() {
  // Built on first use: a scene whose steps assemble never pays for them.
  if (product_.rotation.size() != 9 * elements_.size()) product_.Build(mesh_, elements_);
}

void ElasticTetForce::ElementProductArrays::ReserveTeam(int threads, int dofs) {
  const size_t size = size_t(threads) * PartialStride(dofs);
  if (threads > 1 && partial.size() < size) partial.assign(size, 0.0);
}

void ElasticTetForce::ElementProductArrays::AddElementSums(const double* y, int begin, int end, double sign,
                                                          Eigen::VectorXd& out) {
  const int count = int(mu_volume.size()), threads = omp_get_num_threads();
  auto scatter = [&](double* to, double factor) {
    for (int a = 0; a < 4; ++a)
      for (int e = begin; e < end; ++e) {
        double* node = to + offset[size_t(a * count + e)];
        const double* slot = y + size_t(3 * a * count + e);
        node[0] += factor * slot[0], node[1] += factor * slot[count], node[2] += factor * slot[2 * count];
      }
  };
  if (threads == 1) {
    scatter(out.data(), sign);
    return;
  }
  const int dofs = int(out.size());
  const size_t stride = PartialStride(dofs);
  double* own = partial.data() + size_t(omp_get_thread_num()) * stride;
  std::fill(own, own + dofs, 0.0);
  scatter(own, 1.0);
#pragma omp barrier
#pragma omp for schedule(static)
  for (int i = 0; i < dofs; ++i) {
    double sum = 0;
    for (int p = 0; p < threads; ++p) sum += partial[size_t(p) * stride + size_t(i)];
    out[i] += sign * sum;
  }
}

void ElasticTetForce::ElementProductArrays::Build(const TetMesh& mesh, const std::vector<TetElement>& elements) {
  const int count = int(elements.size());
  offset.resize(4 * size_t(count));
  rotation.assign(9 * size_t(count), 0.0);
  rest_inverse.resize(9 * size_t(count));
  mu_volume.resize(size_t(count));
  lambda_volume.resize(size_t(count));
  element_out.assign(12 * size_t(count), 0.0);
  status.assign(size_t(count), 0);
  inverted.assign(size_t(count), 0);
  for (int t = 0; t < count; ++t) {
    const TetElement& e = elements[size_t(t)];
    for (int a = 0; a < 4; ++a) offset[size_t(a * count + t)] = 3 * mesh.tets[size_t(t)][size_t(a)];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) rest_inverse[size_t((3 * i + j) * count + t)] = e.rest_inverse(i, j);
    mu_volume[size_t(t)] = e.volume_m3 * e.mu_Pa;
    lambda_volume[size_t(t)] = e.volume_m3 * e.lambda_Pa;
  }
  rotations_current = false;
}

Eigen::Matrix3d ElasticTetForce::JacobianDiagonalBlock(int node, double stiffness_scale, double damping_scale) const {
  const double scale = stiffness_scale + (last_dynamic_ && beta_s_ > 0 ? beta_s_ * damping_scale : 0.0);
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (int t : node_elements_[size_t(node)]) {
    const Tet& n = mesh_.tets[size_t(t)];
    const int a = int(std::find(n.begin(), n.end(), node) - n.begin());
    const TetElement& e = elements_[size_t(t)];
    const Eigen::Vector3d g = e.shape_gradients.row(a).transpose();
    const Eigen::Vector3d h = rotations_[size_t(t)] * g;
    sum += StiffnessBlock(e, h, h, g.dot(g));
  }
  return scale * sum;
}

bool ElasticTetForce::UseDefiniteJacobian(bool definite) {
  if (formulation_ != ElasticFormulation::kCorotational || tangent_ != CorotationalTangent::kConsistent) return false;
  definite_ = definite;
  return true;
}

double ElasticTetForce::PotentialEnergy(const SystemState& state) const {
  // V * SED with the rotations of the last AddForce (identity for linear FEM).
  double energy = 0;
  for (size_t t = 0; t < elements_.size(); ++t) {
    const Tet& n = mesh_.tets[t];
    const TetElement& e = elements_[t];
    const Eigen::Matrix3d F = DeformationGradient(e, state.x_m.segment<3>(3 * n[0]), state.x_m.segment<3>(3 * n[1]),
                                                  state.x_m.segment<3>(3 * n[2]), state.x_m.segment<3>(3 * n[3]));
    const Eigen::Matrix3d G = rotations_[t].transpose() * F;
    Eigen::Matrix3d eps = 0.5 * (G + G.transpose());
    eps.diagonal().array() -= 1.0;
    energy += e.volume_m3 * (e.mu_Pa * (eps.array() * eps.array()).sum() + 0.5 * e.lambda_Pa * eps.trace() * eps.trace());
  }
  return energy;
}

void ElasticTetForce::ComputeNodeRotations(std::vector<Eigen::Matrix3d>& node_rotations) const {
  node_rotations.resize(node_elements_.size());
  // From the last call's rotation: the nodes turn little between calls (1-2 Newton steps
  // instead of 3-4 from the identity).
  node_quaternions_.resize(node_elements_.size(), Eigen::Quaterniond::Identity());
  node_rotation_sums_.resize(node_elements_.size());
  const int nodes = int(node_elements_.size());
  // Each thread a range of nodes starting at a multiple of 4 (ExtractRotations' batches).
#pragma omp parallel if (omp_get_max_threads() > 1 && nodes >= kParallelNodeRotationsMinNodes)
  {
    const int threads = omp_get_num_threads(), tid = omp_get_thread_num();
    const int begin = int(long(nodes / 4) * tid / threads) * 4;
    const int end = tid + 1 == threads ? nodes : int(long(nodes / 4) * (tid + 1) / threads) * 4;
    for (int i = begin; i < end; ++i) {
      Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
      for (int t : node_elements_[size_t(i)]) sum += rotations_[size_t(t)];
      node_rotation_sums_[size_t(i)] = sum;
    }
    ExtractRotations(end - begin, node_rotation_sums_.data() + begin, node_quaternions_.data() + begin,
                     node_rotations.data() + begin, kNodeLastNewtonStep_rad);
  }
}

}  // namespace sedbridge::fem
