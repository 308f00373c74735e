#pragma once
// Pseudo friction by anisotropic springs (paper III-B): a node in contact is tied
// tangentially to the point of the object where it first touched, with stiffness a*k and
// damping a*b (a = anisotropy factor; a = 0 is frictionless and is simply not built).
// With a Coulomb coefficient mu > 0 the anchor slides so that |f_t| <= mu f_n.

#include <map>
#include <utility>

#include "fem/penalty_contact_force.h"

namespace sedbridge::fem {

class PseudoFrictionForce final : public ForceTerm {
 public:
  /// Reads the contact set of `contact`, which must be evaluated before this term.
  /// @param anisotropy        a, tangential stiffness = a * k_contact
  /// @param coulomb_mu        sliding limit; <= 0 means sticking springs only
  PseudoFrictionForce(const PenaltyContactForce& contact, double anisotropy, double coulomb_mu);

  std::string name() const override { return "pseudo_friction"; }
  void BindMatrix(const SystemMatrix& matrix) override { matrix_ = &matrix; }
  void AddForce(const SystemState& state, Eigen::VectorXd& force_N, JacobianSink* sink) override;
  void EndStep(const SystemState& state) override;
  bool InRestMatrix() const override { return false; }  // springs only at nodes in contact

  size_t num_anchors() const { return anchors_.size(); }

 private:
  /// Tangential spring force for one contact (and whether it slides).
  Eigen::Vector3d TangentialForce(const ActiveContact& c, const Eigen::Vector3d& x,
                                  const Eigen::Vector3d& anchor, bool* sliding) const;

  const PenaltyContactForce& contact_;
  double anisotropy_, mu_;
  const SystemMatrix* matrix_ = nullptr;
  // (node, object) -> anchor point in the object's own frame (moves with the object).
  std::map<std::pair<int, int>, Eigen::Vector3d> anchors_;
};

}  // namespace sedbridge::fem
