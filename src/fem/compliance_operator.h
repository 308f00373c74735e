#pragma once
// The compliance method's operator (the idea of SOFA's PrecomputedConstraintCorrection, kept
// apart from the contact solver as SOFA keeps it): for a linear, quasi-static model with the
// bone fixed the displacement is u = K^-1 f, and contact forces act only on a known set of
// candidate nodes (the skin facing the pad). Two dense blocks of K^-1, computed once (one
// back-substitution per candidate dof, fem/stiffness_inverse.h) and cached on disk with a
// content key and a checksum, answer every step:
//   W = H K^-1 H^T   3c x 3c   candidate displacements from candidate forces (compliance)
//   G = S K^-1 H^T   3s x 3c   displacements of the s nodes the Merkel-layer SED reads
// With face samples (contact points on skin faces between the nodes) W is over the nodes
// and the samples, B W B^T with B the interpolation, and the products go through the nodes.
// Users: fem/compliance_contact.h (the contact QP), fem/compliance_sed_map.h (the SED).
//
// Units: SI throughout (m, N, Pa).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fem/column_products.h"
#include "fem/force_term.h"
#include "fem/system_matrix.h"
#include "fem/tet_mesh.h"

namespace sedbridge::fem {

class ElasticTetForce;

/// A contact point on a skin face: position and displacement are the weighted sums of its
/// nodes' (indices into the candidate nodes, weights >= 0 summing to 1); its force goes to
/// them with the same weights.
struct ContactSample {
  std::array<int, 3> candidate{};
  std::array<double, 3> weight{};
};

struct ComplianceOperatorOptions {
  /// Also keep K^-1 H^T for every node (3 #nodes x 3 #candidates) for the whole deformed
  /// mesh; not read from the disk cache (which holds W and G only).
  bool full_field = false;
  /// Folder for the cache (created if missing); empty = no disk cache.
  std::string cache_dir;
  /// OpenMP threads for the back-substitutions; 0 = OpenMP's default.
  int precompute_threads = 0;
  /// Contact points on skin faces besides the candidate nodes (see ContactSample).
  std::vector<ContactSample> face_samples;
};

/// The model's linear elastic term among `terms`, after checking that every term has a
/// constant Jacobian. Throws std::invalid_argument otherwise (the compliance is K^-1 at rest).
const ElasticTetForce& LinearElasticTermOf(const std::vector<std::unique_ptr<ForceTerm>>& terms);

/// K at rest [N/m] from the model's own terms (quasi-static: stiffness only), into K.
void AssembleRestStiffness(const TetMesh& mesh, const std::vector<std::unique_ptr<ForceTerm>>& terms, SystemMatrix& K);

/// The node scratch of the products through the nodes (B^T f: face samples' forces spread
/// onto their nodes). Each user of an operator holds its own, so one operator, built once,
/// is shared read-only by several contacts (a hand's fingers on one leader model).
struct NodeForceScratch {
  Eigen::VectorXd node_force, node_u;
  std::vector<int> forced_nodes;
  std::vector<char> node_forced;
};


class ComplianceOperator {
 public:
  /// @param mesh            rest mesh (must outlive this object)
  /// @param K               stiffness at rest [N/m] (AssembleRestStiffness)
  /// @param candidate_nodes nodes that may touch (mesh indices, unique)
  /// @param sed_nodes       nodes whose displacements the SED reads (G's rows)
  /// Throws std::invalid_argument for bad candidates or face samples, or a singular K.
  ComplianceOperator(const TetMesh& mesh, const SystemMatrix& K, std::vector<int> candidate_nodes,
                     std::vector<int> sed_nodes, ComplianceOperatorOptions options = {});

  int num_candidates() const { return int(candidates_.size()); }
  const TetMesh& mesh() const { return mesh_; }
  /// Contact points: the candidate nodes, then the face samples.
  int num_samples() const { return int(rest_samples_m_.cols()); }
  const std::vector<int>& candidate_nodes() const { return candidates_; }
  /// Per contact point: its mesh node (a face sample's first vertex).
  const std::vector<int>& sample_nodes() const { return sample_node_; }
  const Eigen::Matrix3Xd& sample_rest_positions_m() const { return rest_samples_m_; }
  const std::vector<int>& sed_nodes() const { return sed_nodes_; }
  const std::vector<ContactSample>& face_samples() const { return options_.face_samples; }
  /// W over the contact points [m/N] and G over the candidate nodes [m/N].
  const Eigen::MatrixXd& W() const { return W_; }
  const Eigen::MatrixXd& G() const { return G_; }
  bool has_full_field() const { return F_.size() > 0; }

  /// u_samples += W f over `items`: the force force(item) [N] at contact point
  /// sample_of(item) (zero forces skipped).
  template <typename Items, typename SampleOf, typename Force>
  void AddWTimes(const Items& items, const SampleOf& sample_of, const Force& force, Eigen::VectorXd& u_samples,
                 NodeForceScratch& scratch) const;
  /// Spreads a contact point's force [N] onto its nodes (the node scratch); TakeNodeForces
  /// then hands them out.
  void AddSampleForce(int sample, const Eigen::Vector3d& f_N, NodeForceScratch& scratch) const;
  /// Calls take(node, force) for every candidate node with a force in the scratch, in the
  /// order they got one, and clears them.
  template <typename Take>
  void TakeNodeForces(const Take& take, NodeForceScratch& scratch) const;
  /// A zeroed scratch of this operator's size.
  NodeForceScratch MakeScratch() const;
  /// Every node's position [m] (3 #nodes) under the contact points' forces f_samples_N
  /// (3 #samples) at `loaded`; full_field only (empty otherwise).
  Eigen::VectorXd FullPositions(const std::vector<int>& loaded, const Eigen::VectorXd& f_samples_N) const;

  double precompute_s() const { return precompute_s_; }
  bool loaded_from_cache() const { return loaded_from_cache_; }
  const std::string& cache_file() const { return cache_file_; }
  const std::string& cache_rejected_reason() const { return cache_rejected_; }

 private:
  void CheckInputs(int num_nodes) const;
  void Precompute(const SystemMatrix& K);
  bool LoadCache(std::uint64_t key);
  void SaveCache(std::uint64_t key) const;
  void AddFaceSamples();
  /// y += A (the node scratch) over the nodes with a force, which are then cleared.
  template <typename Matrix>
  void ApplyNodeForces(const Matrix& A, Eigen::VectorXd& y, NodeForceScratch& scratch) const;
  /// u_samples += B u_nodes.
  void AddToSamples(const Eigen::VectorXd& u_nodes, Eigen::VectorXd& u_samples) const;

  const TetMesh& mesh_;
  std::vector<int> candidates_, sample_node_, sed_nodes_;
  ComplianceOperatorOptions options_;
  Eigen::MatrixXd W_, G_, F_;  // F_: K^-1 H^T for every dof (full_field only)
  Eigen::MatrixXd W_nodes_;    // face samples: W over the nodes (G_ and F_ stay over the nodes)
  Eigen::Matrix3Xd rest_samples_m_;
  double precompute_s_ = 0;
  bool loaded_from_cache_ = false;
  std::string cache_file_, cache_rejected_;
};

template <typename Take>
void ComplianceOperator::TakeNodeForces(const Take& take, NodeForceScratch& scratch) const {
  for (int node : scratch.forced_nodes) {
    take(node, Eigen::Vector3d(scratch.node_force.segment<3>(3 * node)));
    scratch.node_force.segment<3>(3 * node).setZero();
    scratch.node_forced[size_t(node)] = 0;
  }
  scratch.forced_nodes.clear();
}

template <typename Matrix>
void ComplianceOperator::ApplyNodeForces(const Matrix& A, Eigen::VectorXd& y, NodeForceScratch& scratch) const {
  TakeNodeForces([&](int node, const Eigen::Vector3d& f) { column_products::AddColumns3(A, node, f, y); }, scratch);
}

template <typename Items, typename SampleOf, typename Force>
void ComplianceOperator::AddWTimes(const Items& items, const SampleOf& sample_of, const Force& force,
                                   Eigen::VectorXd& u_samples, NodeForceScratch& scratch) const {
  if (options_.face_samples.empty()) {
    for (int item : items) {
      const Eigen::Vector3d f = force(item);
      if (!f.isZero(0.0)) column_products::AddColumns3(W_, sample_of(item), f, u_samples);
    }
    return;
  }
  for (int item : items) {
    const Eigen::Vector3d f = force(item);
    if (!f.isZero(0.0)) AddSampleForce(sample_of(item), f, scratch);
  }
  if (scratch.forced_nodes.empty()) return;  // no force (a press without shear: the tangential part)
  scratch.node_u.setZero();
  ApplyNodeForces(W_nodes_, scratch.node_u, scratch);
  AddToSamples(scratch.node_u, u_samples);
}

}  // namespace sedbridge::fem
