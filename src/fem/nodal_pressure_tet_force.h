#pragma once
// Average nodal pressure tetrahedron (the idea of Bonet & Burton 1998), corotational: the
// volumetric strain is averaged over the elements around each node, the deviatoric part
// stays per element. Linear tets at nu = 0.48 lock because every element must keep its
// own volume (one constraint per element, ~5-6 elements per node); with one volume
// constraint per node the mesh has ~3 DOF per constraint and no longer locks.
//
// Split of the energy:
//   W = sum_e V_e mu dev(eps_e):dev(eps_e)          (ElasticTetForce, deviatoric_only)
//     + sum_P V_P kappa_P theta_P^2 / 2             (this term)
// eps_e = sym(R_e^T F_e) - I (small strain in the element's rotated frame),
// theta_e = tr(eps_e) = tr(R_e^T F_e) - 3, kappa = lambda + 2 mu / 3, and per patch
// P = (node i, material m): V_P = sum_{e in P} V_e / 4, theta_P = sum_{e in P} (V_e/4) theta_e / V_P.
// Patches are per material so a node on a layer interface does not average a soft
// layer's volume change with a stiff one's.
//
// Force: f_a = -sum_e V_e pbar_e R_e g_a, pbar_e = mean of kappa_P theta_P over e's four
// patches (d tr(R^T F) / dx is exactly R g: the rotation's variation drops out of the
// trace). Stiffness: K = sum_P V_P kappa_P b_P b_P^T with b_P = d theta_P / dx (R held
// fixed, as the corotational element does), which couples all nodes of a patch: the
// matrix pattern grows from the 1-ring to the 2-ring of each node. With the elastic term's
// consistent tangent, R's variation adds per element the twist terms of the isotropic
// stress pbar (CorotationalTwistTerms).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "fem/elastic_tet_force.h"
#include "fem/force_term.h"
#include "fem/slab_partition.h"

namespace sedbridge::fem {

class NodalPressureTetForce final : public ForceTerm {
 public:
  /// @param elastic the scene's ElasticTetForce built with deviatoric_only = true on the
  ///        same mesh (kept by reference; must outlive this term). It must come before
  ///        this term in the simulation's term list: its element rotations of the same
  ///        assembly are used here. Its Rayleigh beta [s] is used for this term's damping too.
  /// Throws std::invalid_argument if `elastic` is not deviatoric-only.
  explicit NodalPressureTetForce(const ElasticTetForce& elastic, double rayleigh_beta_s = 0.0);

  std::string name() const override { return "nodal_pressure"; }
  void AppendCoupledNodes(std::vector<std::pair<int, int>>& pairs) const override;
  void BindMatrix(const SystemMatrix& matrix) override;
  void AddForce(const SystemState& state, Eigen::VectorXd& force_N, JacobianSink* sink) override;
  bool JacobianIsConstant() const override { return elastic_.formulation() == ElasticFormulation::kLinear; }
  /// sum_P V_P kappa_P theta_P^2 / 2 [J] with the elastic term's last rotations.
  double PotentialEnergy(const SystemState& state) const override;
  /// With the elastic term's consistent tangent: true drops this term's twist terms too.
  bool UseDefiniteJacobian(bool definite) override;

  /// Volumetric strain of one element, tr(R^T F) - 3 (R = I for linear FEM).
  static double ElementVolumetricStrain(const Eigen::Matrix3d& F, const Eigen::Matrix3d& R);

  // Patch structure, for the SED evaluator.
  int num_patches() const { return int(patch_volume_.size()); }
  /// Patch of corner a of element t.
  int patch_of(int t, int a) const { return element_patch_[size_t(t)][size_t(a)]; }
  /// Elements of patch p: patch_elements()[patch_offsets()[p] .. patch_offsets()[p+1]).
  const std::vector<int>& patch_offsets() const { return patch_offsets_; }
  const std::vector<int>& patch_elements() const { return patch_elements_; }
  /// V_P [m^3] and kappa_P [Pa] of each patch.
  const std::vector<double>& patch_volume_m3() const { return patch_volume_; }
  const std::vector<double>& patch_bulk_Pa() const { return patch_bulk_; }
  /// theta_P from element volumetric strains theta_e given for all elements.
  void PatchStrains(const Eigen::VectorXd& element_theta, Eigen::VectorXd& patch_theta) const;
  /// Patch volumetric strain at the last AddForce.
  const Eigen::VectorXd& patch_theta() const { return patch_theta_; }

 private:
  /// This patch's K (and D, and K v) into the sink, b scratch of its node count.
  void AddPatchJacobian(int p, bool damping, JacobianSink* sink, std::vector<Eigen::Vector3d>& b);

  const ElasticTetForce& elastic_;
  double beta_s_;
  std::vector<std::array<int, 4>> element_patch_;
  std::vector<int> patch_offsets_, patch_elements_;   // CSR: elements of each patch
  std::vector<int> node_offsets_, patch_nodes_;       // CSR: distinct nodes of each patch
  std::vector<std::array<int, 4>> entry_local_;        // per (patch, element) entry: corners' local node index
  std::vector<double> patch_volume_, patch_bulk_;
  std::vector<int> slot_offsets_, slots_;             // per patch: n_P x n_P slots, row-major
  Eigen::VectorXd element_theta_, patch_theta_, patch_pressure_;
  std::vector<std::vector<Eigen::Vector3d>> thread_b_;  // scratch per thread: b_P per local node
  size_t widest_patch_ = 0;
  SlabPartition partition_;                             // patches by slab (threads = 0: to build)
  std::vector<std::array<int, 16>> element_slots_;    // corotational: element node-pair slots
  bool definite_ = false;
};

}  // namespace sedbridge::fem
