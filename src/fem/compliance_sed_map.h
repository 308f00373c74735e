#pragma once
// The compliance method's Merkel-layer SED: the contact forces at the candidate nodes go
// through G = S K^-1 H^T (fem/compliance_operator.h) to the displacements of the nodes the
// SED reads, then the linear SED of the layer's elements (fem/tet_sed.h) is averaged to its
// vertices. G is read in single precision (half the bytes a step reads; ~1e-7 relative in the
// displacements), and a node whose force keeps its direction from one SED to the next (a
// plane's contacts) is read through one kept column G(:, node) d instead of three.
//
// Units: SI (m, N, Pa).

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "fem/strain_energy_density.h"
#include "fem/tet_mesh.h"

namespace sedbridge::fem {

struct ComplianceSedMapOptions {
  /// Memory for the kept columns [MiB]; 0 = none (every node through G's three columns).
  double kept_columns_MiB = 64;
  /// The two passes run on the caller's OpenMP team only from these sizes on: entries of G
  /// read by the product, and elements of the SED pass.
  double parallel_min_entries = 1.5e6;
  int parallel_min_elements = 4000;
};

class ComplianceSedMap {
 public:
  /// @param elastic   the model's linear elastic term (must outlive this object)
  /// @param vertices  nodes where the SED is wanted (the Merkel layer's vertices)
  ComplianceSedMap(const ElasticTetForce& elastic, std::vector<int> vertices, ComplianceSedMapOptions options = {});
  ~ComplianceSedMap();

  const std::vector<int>& vertices() const;
  /// Nodes whose displacements the SED reads (those of the elements around vertices()):
  /// the rows of G, in this order.
  const std::vector<int>& sed_nodes() const { return sed_nodes_; }
  /// Takes G [m/N] (3 #sed_nodes x 3 #candidates) in single precision.
  void BindOperator(const Eigen::MatrixXd& G_m_N);

  /// One SED: BeginForces(at most `count` forces), AddNodeForce for each loaded candidate
  /// (its column of G and its force [N]), then ComputeDisplacements and ComputeSed.
  void BeginForces(Eigen::Index count);
  void AddNodeForce(int candidate, const Eigen::Vector3d& f_N);
  /// The SED nodes' displacements [m] (3 #sed_nodes) from the forces added.
  const Eigen::VectorXd& ComputeDisplacements();
  /// Vertex SED [Pa] in the order of vertices(), from the last displacements.
  void ComputeSed(Eigen::VectorXd& vertex_sed_Pa);

  /// The SED nodes' displacements [m] of the last ComputeDisplacements.
  const Eigen::VectorXd& displacements_m() const { return u_s_m_; }
  /// Small strain of every SED element [-] (6 per element: xx yy zz xy xz yz, tensor
  /// components; elements in the evaluator's order) from SED-node displacements u_s [m].
  void ElementStrains(const Eigen::VectorXd& u_s_m, Eigen::VectorXd& strain) const;
  const std::vector<double>& element_mu_Pa() const { return mu_Pa_; }
  const std::vector<double>& element_lambda_Pa() const { return lambda_Pa_; }
  /// The vertex average as a sparse map: vertex v's SED is the sum over k in
  /// [start[v], start[v+1]) of weight[k] * the SED of element element[k].
  void VertexAverage(std::vector<int>& start, std::vector<int>& element, std::vector<double>& weight) const;

  /// SED columns G(:, node) d computed (kept for reuse) and node forces read through one.
  std::uint64_t columns_kept() const { return columns_kept_; }
  std::uint64_t kept_reads() const { return kept_reads_; }

 private:
  /// The kept column's slot for `candidate` when its force f is along the direction it had
  /// at the last SED (f = coefficient * that direction, to 1e-12 relative), else -1.
  int KeptColumn(int candidate, const Eigen::Vector3d& f, double* coefficient);

  ComplianceSedMapOptions options_;
  std::unique_ptr<VertexSedEvaluator> sed_;
  std::vector<int> sed_nodes_;
  // The SED elements (in the order of sed_->elements()), structure of arrays: node a's
  // offset 3 * (index into sed_nodes_) at [a * count + e], shape gradient (a, q) at
  // [(3 a + q) * count + e], Lame parameters per element.
  std::vector<int> offset_;
  std::vector<double> gradient_, mu_Pa_, lambda_Pa_;
  Eigen::VectorXd element_sed_Pa_, u_s_m_;
  Eigen::MatrixXf G_single_;
  struct KeptDirection {
    Eigen::Vector3d dir = Eigen::Vector3d::Zero();  // unit; zero: none seen
    int slot = -1;                                 // its column in kept_, -1: none
  };
  Eigen::Index kept_budget_ = 0;         // kept columns kept_columns_MiB holds
  std::vector<KeptDirection> direction_;  // per candidate column of G (with a budget)
  Eigen::MatrixXf kept_;                  // kept columns (G's rows, single precision)
  std::vector<int> kept_free_;            // slots given back by a node that turned
  std::vector<int> kept_slots_;           // this SED's kept slots ...
  std::vector<double> kept_coefficients_;  // ... and their coefficients
  std::vector<int> triple_columns_;       // this SED's nodes through three columns ...
  Eigen::Matrix3Xd forces_;               // ... and their forces
  std::uint64_t columns_kept_ = 0, kept_reads_ = 0;
};

}  // namespace sedbridge::fem
