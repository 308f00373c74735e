#pragma once
// Strain energy density (paper eq. 1): element SED = 1/2 sigma:epsilon with the small
// strain measured in the element's corotated frame (so a rigid rotation gives zero);
// vertex SED = mean of the SED of the elements around the vertex.

#include <Eigen/Core>
#include <vector>

#include "fem/elastic_tet_force.h"
#include "fem/nodal_pressure_tet_force.h"

namespace sedbridge::fem {

/// SED [J/m^3 = Pa] of one element given F and its rotation R (R = I for linear FEM).
/// With a deviatoric-only element (lambda = -2 mu / 3) this is the deviatoric part alone.
double ElementSed(const TetElement& e, const Eigen::Matrix3d& F, const Eigen::Matrix3d& R);

/// Evaluates vertex SED on a chosen vertex set, touching only the elements around it
/// (e.g. the Merkel layer: a few hundred vertices of a mesh of thousands of elements).
class VertexSedEvaluator {
 public:
  /// @param elastic   the scene's elastic term (mesh, elements, formulation, warm starts)
  /// @param vertices  node indices where SED is wanted
  /// @param nodal     the scene's nodal pressure term if it has one (must outlive this):
  ///                  element SED is then sigma:eps/2 with the smoothed volumetric part,
  ///                  mu dev(eps):dev(eps) + kappa thetabar^2 / 2, thetabar = mean of the
  ///                  element's four patch strains (= pbar thetabar / 2, pbar = kappa thetabar)
  ///                  (elements outside the vertices' own feed theta with the elastic
  ///                  term's rotations of its last assembly: second-order accurate)
  /// @param averaged  per mesh tet, nonzero = its SED enters the vertex averages (a one-sided
  ///                  value); null = every element around a vertex. A vertex none of whose
  ///                  elements is included averages all of them.
  /// Throws std::invalid_argument for a deviatoric-only `elastic` without `nodal`, or an
  /// `averaged` mask whose size is not the mesh's tet count.
  VertexSedEvaluator(const ElasticTetForce& elastic, std::vector<int> vertices,
                     const NodalPressureTetForce* nodal = nullptr, const std::vector<char>* averaged = nullptr);

  /// Vertex SED [Pa] for positions x (3 * #nodes), in the order of vertices().
  void Evaluate(const Eigen::VectorXd& x_m, Eigen::VectorXd& vertex_sed_Pa);
  /// Element SED [Pa] of elements() from the last Evaluate.
  const Eigen::VectorXd& element_sed_Pa() const { return element_sed_; }

  /// Vertex SED from element SED given for elements() (e.g. from a reduced solver).
  void AverageToVertices(const Eigen::VectorXd& element_sed_Pa, Eigen::VectorXd& vertex_sed_Pa) const;

  const std::vector<int>& vertices() const { return vertices_; }
  const std::vector<int>& elements() const { return elements_; }
  /// Nodes of elements(), sorted: the only displacements Evaluate reads (linear and
  /// corotational elements).
  const std::vector<int>& element_nodes() const { return element_nodes_; }

 private:
  void EvaluateNodalPressure(const Eigen::VectorXd& x_m);
  const ElasticTetForce& elastic_;
  std::vector<int> vertices_;
  std::vector<int> elements_;                  // union of elements around vertices_
  std::vector<int> element_nodes_;             // their nodes, sorted
  std::vector<std::vector<int>> vertex_local_; // per vertex: indices into elements_
  std::vector<Eigen::Quaterniond> warm_;
  // Evaluate's element data (linear and corotational) as structures of arrays (the SED four elements at
  // a time), built on first use: node a's 3 * index at [a * count + k], Dm^-1 (i, j) at
  // [(3 i + j) * count + k]; per element mu, lambda and the vector pass's status.
  struct SedArrays {
    std::vector<int> offset;
    std::vector<double> rest_inverse, mu, lambda, status;
  };
  SedArrays arrays_;
  Eigen::VectorXd element_sed_;
  // Nodal pressure: the patches of elements_ and every element feeding them ("ring").
  const NodalPressureTetForce* nodal_ = nullptr;
  std::vector<int> ring_;                       // element ids; elements_ come first
  std::vector<int> ring_local_;                 // element id -> index in ring_, -1 if absent
  std::vector<int> patches_;                    // patch ids used by elements_
  std::vector<int> patch_local_;                // patch id -> index in patches_, -1 if absent
  std::vector<Eigen::Quaterniond> ring_warm_;
  Eigen::VectorXd ring_theta_, patch_theta_;
  std::vector<Eigen::Matrix3d> ring_F_, ring_R_;
};

}  // namespace sedbridge::fem
