#pragma once
// Elastic force of linear tetrahedra: corotational (per-element rotation, paper III-B) or
// plain linear FEM. Optional stiffness-proportional (Rayleigh beta) damping.

#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "common/no_copy_no_move.h"
#include "fem/force_term.h"
#include "fem/slab_partition.h"
#include "fem/node_rotation_source.h"
#include "fem/system_matrix.h"
#include "fem/tet_element.h"

namespace sedbridge::fem {

enum class ElasticFormulation { kCorotational, kLinear };

/// Stiffness of the corotational element handed to the solver.
/// - kWarped: R K0 R^T (SOFA, the paper). It misses how R turns with the nodes, so Newton
///   converges linearly once elements rotate (about a factor 3 per iteration on the paper's
///   press).
/// - kConsistent: the derivative of the corotational force, rotation included: R K0 R^T
///   plus, per element, three rank-one "twist" terms. Rotating the element in the (i, j)
///   principal plane of its stretch S has stiffness V (sigma_i + sigma_j) / (s_i + s_j)
///   (principal stresses sigma_i, principal stretches s_i), which R K0 R^T sets to 0.
///   Newton then converges quadratically. Under compression a twist stiffness is negative,
///   so the matrix can be indefinite: UseDefiniteJacobian(true) drops the twist terms
///   (the warped tangent) until it is called with false. Elements inverted or close to it
///   in a plane (s_i + s_j <= 0.5) keep the warped stiffness there.
enum class CorotationalTangent { kWarped, kConsistent };

/// Per twist plane, the 4 node blocks of one twist vector.
using TwistVectors = std::array<std::array<Eigen::Vector3d, 4>, 3>;

/// The consistent corotational tangent's twist terms of one element (CorotationalTangent):
/// K += sum_k sign_k t_k t_k^T for up to three twist planes; returns how many were written.
/// @param R, F               element rotation and deformation gradient
/// @param with_element_stress include the element's own stress 2 mu eps + lambda tr(eps) I
/// @param pressure_Pa        an isotropic stress added to it (the nodal pressure term's
///                           pbar; 0 for the plain element)
/// Planes with s_i + s_j <= 0.5 (near inversion) or zero stiffness are left out.
int CorotationalTwistTerms(const TetElement& e, const Eigen::Matrix3d& R, const Eigen::Matrix3d& F,
                           bool with_element_stress, double pressure_Pa, TwistVectors& t, std::array<double, 3>& sign);

class ElasticTetForce final : public ForceTerm, public NodeRotationSource {
 public:
  // Holds its own rest-stiffness SystemMatrix and slots bound to the system matrix.
  SEDBRIDGE_NO_COPY_NO_MOVE(ElasticTetForce)

  /// @param mesh            rest mesh (kept by reference; must outlive the term)
  /// @param formulation     corotational or linear
  /// @param rayleigh_beta_s stiffness-proportional damping D = beta K [s]; 0 = none
  /// @param deviatoric_only true: only the deviatoric part 2 mu dev(eps) (lambda replaced
  ///        by -2 mu / 3); the volumetric part is then another term's (NodalPressureTetForce)
  ElasticTetForce(const TetMesh& mesh, ElasticFormulation formulation, double rayleigh_beta_s = 0.0,
                  bool deviatoric_only = false);

  std::string name() const override;
  void AppendCoupledNodes(std::vector<std::pair<int, int>>& pairs) const override;
  void BindMatrix(const SystemMatrix& matrix) override;
  void AddForce(const SystemState& state, Eigen::VectorXd& force_N, JacobianSink* sink) override;
  bool JacobianIsConstant() const override { return formulation_ == ElasticFormulation::kLinear; }
  double PotentialEnergy(const SystemState& state) const override;
  bool UseDefiniteJacobian(bool definite) override;
  /// Linear, or corotational with the warped tangent (R K0 R^T): the consistent tangent's
  /// twist terms are assembled.
  bool AppliesJacobian() const override;
  /// (stiffness_scale + damping_scale beta) R K0 R^T v, element by element in stress form
  /// (the rotations of the last AddForce; beta only if that state was dynamic).
  void AddJacobianTimes(double stiffness_scale, double damping_scale, const Eigen::VectorXd& v,
                        Eigen::VectorXd& out) override;
  Eigen::Matrix3d JacobianDiagonalBlock(int node, double stiffness_scale, double damping_scale) const override;

  /// Rotation of each element at the last AddForce (identity for linear FEM).
  const std::vector<Eigen::Matrix3d>& rotations() const { return rotations_; }
  /// Per-node rotation (closest rotation to the sum of the adjacent element rotations),
  /// for the warped preconditioner. Computed on demand from rotations().
  void ComputeNodeRotations(std::vector<Eigen::Matrix3d>& node_rotations) const override;
  /// Elements with det F <= 0 at the last AddForce.
  int inverted_elements() const { return inverted_elements_; }
  /// Corotational force without Jacobian (vectorized, four elements at a time, up to
  /// rotation_step4::kMaxRotationSteps warm Newton steps of each rotation): elements whose
  /// rotation took ExtractRotation's full iteration instead at the last such AddForce.
  int scalar_rotations() const { return scalar_rotations_; }

  const TetMesh& mesh() const { return mesh_; }
  const std::vector<TetElement>& elements() const { return elements_; }
  ElasticFormulation formulation() const { return formulation_; }
  bool deviatoric_only() const { return deviatoric_only_; }
  /// Corotational stiffness (ignored by linear FEM). Default kWarped.
  void set_corotational_tangent(CorotationalTangent tangent) { tangent_ = tangent; }
  CorotationalTangent corotational_tangent() const { return tangent_; }

 private:
  const TetMesh& mesh_;
  ElasticFormulation formulation_;
  double beta_s_;
  bool deviatoric_only_;
  CorotationalTangent tangent_ = CorotationalTangent::kWarped;
  bool definite_ = false;  // UseDefiniteJacobian: the warped tangent for now
  std::vector<TetElement> elements_;
  std::vector<std::array<int, 16>> slots_;
  std::vector<Eigen::Quaterniond> quaternions_;  // warm starts
  std::vector<Eigen::Matrix3d> rotations_;
  std::vector<std::vector<int>> node_elements_;
  // Warm starts of ComputeNodeRotations (a cache: the answer is the same to round-off).
  mutable std::vector<Eigen::Quaterniond> node_quaternions_;
  mutable std::vector<Eigen::Matrix3d> node_rotation_sums_;
  int inverted_elements_ = 0;
  /// Element kernel: force into `force`, Jacobian blocks into `values`/`k_times_v` (laid
  /// out like sink's matrix). Returns 1 if the element is inverted.
  int AccumulateElement(int t, const SystemState& state, bool force, Eigen::VectorXd& force_N, JacobianSink* sink,
                        double* values, Eigen::VectorXd* k_times_v);
  /// V R sigma of element t at rotation R and deformation gradient F (and the state's
  /// velocity when `damping`): node a's force is minus this times its shape gradient.
  Eigen::Matrix3d VolumeRotatedStress(int t, const Eigen::Matrix3d& R, const Eigen::Matrix3d& F,
                                      const SystemState& state, bool damping) const;
  /// The corotational force without Jacobian, vectorized across elements (warm Newton steps
  /// of each rotation; ExtractRotation for the elements they do not settle). Returns the
  /// number of inverted elements.
  int AddCorotationalForceVectorized(const SystemState& state, Eigen::VectorXd& force_N);
  /// out += scale R K0 R^T v over element t's nodes, in stress form.
  void AddElementStiffnessTimes(int t, const Eigen::Matrix3d& R, double scale, const Eigen::VectorXd& v,
                                Eigen::VectorXd& out) const;
  int scalar_rotations_ = 0;
  bool last_dynamic_ = false;  // the last AddForce's state was dynamic (its damping applies)
  // AddJacobianTimes' element data as structures of arrays (see ElementStiffnessTimes in
  // the .cpp), built on first use; the rotations copied once after each AddForce.
  struct ElementProductArrays {
    std::vector<int> offset;                     // 3 * node, [a * count + e]
    std::vector<double> rotation, rest_inverse;  // [(3 i + j) * count + e]
    std::vector<double> mu_volume, lambda_volume;
    // Per-element nodal values of one pass (minus the force, or a product), summed to the
    // nodes before the next pass starts: [(3 a + k) * count + e].
    std::vector<double> element_out;
    std::vector<double> status, inverted;         // CorotationalForces' flags per element
    // Per thread of a team, its elements' sums by degree of freedom (thread p's at
    // p * PartialStride(dofs)), for the team's reduction.
    std::vector<double> partial;
    /// Whole cache lines of doubles per thread's sums: no line shared by two threads.
    static size_t PartialStride(int dofs) { return (size_t(dofs) + 7) / 8 * 8; }
    bool rotations_current = false;
    void Build(const TetMesh& mesh, const std::vector<TetElement>& elements);
    /// Sizes `partial` for a team of up to `threads` (before the parallel region).
    void ReserveTeam(int threads, int dofs);
    /// out += sign * the sums of elements [begin, end)'s slots of y (laid out as element_out)
    /// by node, for the calling thread's own elements. Alone: straight into out. In a team
    /// (every thread calls it, after writing its own elements' y): each thread sums the slots
    /// it wrote itself, still in its own cache, into its own partial sums, and the team then
    /// adds the partial sums to out range by range. A node's slots gathered across the team
    /// instead read half of them from the other core's cache, and cost two cores more than one
    /// did (B_fine, docs/lab-notes/2026-11-28-fe-step-speed-later-runs.md,
    /// "each thread sums its own elements' slots").
    void AddElementSums(const double* y, int begin, int end, double sign, Eigen::VectorXd& out);
  };
  ElementProductArrays product_;
  void EnsureProductArrays();
  Eigen::VectorXd rest_product_;
  // Threads > 1: per-thread partial sums (thread 0 writes the real buffers), reduced once.
  std::vector<std::vector<double>> thread_values_;
  std::vector<Eigen::VectorXd> thread_force_, thread_k_times_v_;
  SlabPartition partition_;  // elements by slab for the team size (threads = 0: to build)
  double own_values_ = 0;    // values of the matrix the elements' blocks occupy
  // Linear FEM: K0 assembled once; the force is then one sparse product a step.
  SystemMatrix rest_stiffness_;
  Eigen::VectorXd rest_positions_, work_, k_times_work_;
};

}  // namespace sedbridge::fem
