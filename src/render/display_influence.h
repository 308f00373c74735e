#pragma once
// What a display's commands do to the leader's Merkel layer, linear about the preloaded
// state: the layer's element strains are eps_e(u) = eps0_e + E_e u for a command vector u
// (eps0: the preload's strain; E_e: each actuator's strain per unit command), so the SED of
// any command vector is a quadratic form per element, the tet SED of fem/tet_sed.h,
// averaged to the layer's vertices
// as the bridge's SED is (S = A W). Built once per display and leader model; then the SED of
// a command vector costs one product with the 6 #elements x #actuators strain matrix (its
// Jacobian one more), microseconds. (Per-vertex #actuators^2 forms would cost #vertices x
// #actuators^2 instead: 16 times more at 64 actuators, measured slower already at 16.)

#include <Eigen/Core>
#include <vector>

namespace sedbridge::render {

/// Strain components in this order: xx, yy, zz, xy, xz, yz (tensor components, not
/// engineering shear) [-].
constexpr int kStrainComponents = 6;

/// The per-element description the quadratic forms are built from.
struct ElementStrainInfluence {
  /// 6 #elements x #actuators: element e's strain per unit command of each actuator
  /// [1/command unit], rows 6e..6e+5.
  Eigen::MatrixXd strain_per_command;
  /// 6 #elements: the strain of the preloaded state with every command 0 [-].
  Eigen::VectorXd preload_strain;
  Eigen::VectorXd mu_Pa, lambda_Pa;  ///< per element
  /// Vertex average: vertex v's SED is the sum over k in [start[v], start[v+1]) of
  /// weight[k] * element SED of element[k].
  std::vector<int> vertex_start, vertex_element;
  std::vector<double> vertex_weight;
};

/// The quadratic forms of the vertex SED in the commands.
class DisplayInfluence {
 public:
  DisplayInfluence() = default;
  /// Throws std::invalid_argument for inconsistent sizes or non-finite entries.
  explicit DisplayInfluence(const ElementStrainInfluence& elements);

  int num_actuators() const { return num_actuators_; }
  int num_vertices() const { return int(in_.vertex_start.size()) - 1; }
  /// Vertex SED [Pa] of command vector u (#actuators), into sed_Pa (#vertices).
  void Sed(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa) const;
  /// The same and its Jacobian dS/du [Pa / command unit] (#vertices x #actuators).
  void SedAndJacobian(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa, Eigen::MatrixXd& jacobian) const;
  /// Vertex SED of the preloaded state with every command 0 [Pa].
  const Eigen::VectorXd& preload_sed_Pa() const { return preload_sed_Pa_; }

 private:
  /// Element strains eps_ = eps0 + E u and element SEDs element_sed_ at u.
  void ElementSeds(const Eigen::VectorXd& u) const;
  void AverageToVertices(const Eigen::VectorXd& element, Eigen::VectorXd& vertex) const;

  int num_actuators_ = 0;
  ElementStrainInfluence in_;
  Eigen::VectorXd preload_sed_Pa_;
  mutable Eigen::VectorXd eps_, element_sed_;
  mutable Eigen::MatrixXd element_gradient_;  // dW_e/du, #elements x #actuators
};

}  // namespace sedbridge::render
