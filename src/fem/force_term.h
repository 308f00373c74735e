#pragma once
// The one small interface every FE effect implements: add your force, and (when asked)
// your stiffness K = -df/dx and damping D = -df/dv into the system matrix. A scene builds
// only the terms it lists, so an unused effect costs nothing.

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "fem/system_matrix.h"

namespace sedbridge::fem {

/// Positions and velocities of all nodes, stacked (3 * #nodes), SI.
struct SystemState {
  const Eigen::VectorXd& x_m;
  const Eigen::VectorXd& v_m_s;
  double t_s;
  /// False for quasi-static solves: velocity-dependent (damping) forces are left out.
  bool dynamic = true;
};

/// Receives Jacobian blocks. The integrator sets the scales: backward Euler assembles
/// M + h D + h^2 K (stiffness_scale = h^2, damping_scale = h); quasi-static assembles K.
/// When `velocity` is set it also accumulates K v (backward Euler's right-hand side
/// h f0 - h^2 K v0 needs it).
struct JacobianSink {
  SystemMatrix* matrix = nullptr;
  double stiffness_scale = 1.0;
  double damping_scale = 0.0;
  const Eigen::VectorXd* velocity = nullptr;
  Eigen::VectorXd* stiffness_times_velocity = nullptr;

  /// Block (i, j) of K = -df/dx and, if given, of D = -df/dv. Callers writing distinct
  /// block rows may call this concurrently.
  void Add(int slot, int i, int j, const Eigen::Matrix3d& K, const Eigen::Matrix3d* D = nullptr) {
    AddTo(matrix->values(), stiffness_times_velocity, slot, i, j, K, D);
  }
  /// Same into other buffers laid out like the matrix and K v (per-thread partial sums).
  void AddTo(double* values, Eigen::VectorXd* k_times_v, int slot, int i, int j, const Eigen::Matrix3d& K,
             const Eigen::Matrix3d* D = nullptr) const {
    matrix->AddBlockTo(values, slot, K, stiffness_scale);
    if (D && damping_scale != 0) matrix->AddBlockTo(values, slot, *D, damping_scale);
    if (velocity) k_times_v->segment<3>(3 * i) += K * velocity->segment<3>(3 * j);
  }
};

class ForceTerm {
 public:
  virtual ~ForceTerm() = default;
  virtual std::string name() const = 0;

  /// Node pairs (i, j), i != j, whose blocks this term writes (diagonals always exist).
  virtual void AppendCoupledNodes(std::vector<std::pair<int, int>>& pairs) const {}
  /// Called once the pattern exists, to cache slots.
  virtual void BindMatrix(const SystemMatrix& matrix) {}

  /// Adds this term's force [N] at `state` into `force_N` (3 * #nodes) and, if `sink` is
  /// non-null, its Jacobian blocks.
  virtual void AddForce(const SystemState& state, Eigen::VectorXd& force_N, JacobianSink* sink) = 0;

  /// Matrix-free steps (fem/step_operator.h): true when this term can apply the Jacobian
  /// of its last AddForce to a vector (AddJacobianTimes, JacobianDiagonalBlock), so that its
  /// blocks need not be assembled. Asked before each assembly (it may depend on the tangent).
  virtual bool AppliesJacobian() const { return false; }
  /// out += (stiffness_scale K + damping_scale D) v [N], with K and D at the state of the
  /// last AddForce (its velocity-dependent part only if that state was dynamic).
  virtual void AddJacobianTimes(double stiffness_scale, double damping_scale, const Eigen::VectorXd& v,
                                Eigen::VectorXd& out) {}
  /// Block (node, node) of stiffness_scale K + damping_scale D at the last AddForce.
  virtual Eigen::Matrix3d JacobianDiagonalBlock(int node, double stiffness_scale, double damping_scale) const {
    return Eigen::Matrix3d::Zero();
  }

  /// True when this term's K and D never change (linear elasticity, fixed springs, dead
  /// loads): if every term says so, the integrator assembles and factorizes once.
  virtual bool JacobianIsConstant() const { return false; }

  /// False for terms whose stiffness comes and goes with the state (contact springs): the
  /// rest matrix a warped preconditioner factorizes leaves them out, whenever it is taken
  /// (fem/newton_system.h); the stiff-node update adds them back where they act.
  virtual bool InRestMatrix() const { return true; }

  /// Called once after each accepted step (not per Newton iteration): stateful terms
  /// (friction anchors) update here.
  virtual void EndStep(const SystemState& state) {}

  /// Terms whose exact Jacobian can be indefinite (the consistent corotational tangent
  /// under compression) switch to a positive definite approximation while `definite` is
  /// true. Returns true if this term has such an approximation (false: nothing changes).
  virtual bool UseDefiniteJacobian(bool definite) { return false; }
  /// Total work-conjugate energy of the term where defined (elastic, springs) [J];
  /// used by stability tests to bound energy. 0 if not meaningful.
  virtual double PotentialEnergy(const SystemState& state) const { return 0.0; }
};

}  // namespace sedbridge::fem
