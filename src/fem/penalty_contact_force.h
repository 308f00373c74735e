#pragma once
// Penalty contact between skin nodes and rigid objects given as signed distance fields
// (paper Fig. 2b): a node inside an object feels f_n = k * depth - b * v_n along the
// object's outward normal (never pulling: f_n >= 0). K = k n n^T and D = b n n^T enter the
// system matrix so stiff penalties stay stable. Contact force = sum of spring forces.

#include <vector>

#include "fem/force_term.h"
#include "fem/stiff_node_source.h"
#include "common/geometry/rigid_object.h"

namespace sedbridge::fem {

struct ContactParams {
  double stiffness_N_m = 1e4;   ///< k_contact, per node
  double damping_N_s_m = 0.5;   ///< b, per node
};

/// One node inside one object at the last evaluation.
struct ActiveContact {
  int node = -1;
  int object = -1;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< object's outward normal
  double depth_m = 0;             ///< penetration (> 0)
  double spring_force_N = 0;      ///< k * depth
  double normal_force_N = 0;      ///< spring + damper, clamped >= 0
  /// Compliance method (fem/compliance_contact.h): which contact sample touched (a
  /// candidate node, or a point on a skin face, whose `node` is then its first vertex).
  int sample = -1;
};

class PenaltyContactForce final : public ForceTerm, public StiffNodeSource {
 public:
  /// @param candidate_nodes nodes that may touch (the skin); objects are in the model frame.
  PenaltyContactForce(std::vector<int> candidate_nodes, std::vector<geometry::RigidObject> objects,
                      ContactParams params);

  std::string name() const override { return "penalty_contact"; }
  void BindMatrix(const SystemMatrix& matrix) override;
  void AddForce(const SystemState& state, Eigen::VectorXd& force_N, JacobianSink* sink) override;
  double PotentialEnergy(const SystemState& state) const override;
  bool InRestMatrix() const override { return false; }

  const std::vector<ActiveContact>& active_contacts() const { return active_; }
  /// The active contacts' nodes: their springs are the stiff part of a step's matrix.
  void AppendStiffNodes(std::vector<int>& nodes) const override;
  /// Sum of spring forces k*depth*n over active contacts, force ON the objects is the
  /// negative. Model frame [N].
  Eigen::Vector3d TotalSpringForce() const;
  /// Sum of spring force magnitudes [N] (the paper's contact force).
  double TotalSpringForceMagnitude() const;

  const std::vector<geometry::RigidObject>& objects() const { return objects_; }
  const ContactParams& params() const { return params_; }

 private:
  std::vector<int> nodes_;
  std::vector<geometry::RigidObject> objects_;
  ContactParams params_;
  std::vector<int> slots_;
  std::vector<ActiveContact> active_;
};

}  // namespace sedbridge::fem
