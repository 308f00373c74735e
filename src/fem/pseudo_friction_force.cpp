#include "fem/pseudo_friction_force.h"

namespace sedbridge::fem {

PseudoFrictionForce::PseudoFrictionForce(const PenaltyContactForce& contact, double anisotropy,
                                         double coulomb_mu)
    : contact_(contact), anisotropy_(anisotropy), mu_(coulomb_mu) {}

Eigen::Vector3d PseudoFrictionForce::TangentialForce(const ActiveContact& c, const Eigen::Vector3d& x,
                                                     const Eigen::Vector3d& anchor, bool* sliding) const {
  const Eigen::Matrix3d tangential = Eigen::Matrix3d::Identity() - c.normal * c.normal.transpose();
  Eigen::Vector3d ft = -anisotropy_ * contact_.params().stiffness_N_m * (tangential * (x - anchor));
  *sliding = false;
  if (mu_ > 0) {
    const double limit = mu_ * c.normal_force_N;
    const double norm = ft.norm();
    if (norm > limit) {
      *sliding = true;
      ft *= (norm > 0 ? limit / norm : 0.0);
    }
  }
  return ft;
}

void PseudoFrictionForce::AddForce(const SystemState& s, Eigen::VectorXd& f, JacobianSink* sink) {
  const double kt = anisotropy_ * contact_.params().stiffness_N_m;
  const double bt = anisotropy_ * contact_.params().damping_N_s_m;
  for (const ActiveContact& c : contact_.active_contacts()) {
    const auto it = anchors_.find({c.node, c.object});
    if (it == anchors_.end()) continue;  // new contact: anchored at the end of this step
    const auto& obj = contact_.objects()[size_t(c.object)];
    const Eigen::Vector3d x = s.x_m.segment<3>(3 * c.node);
    const Eigen::Vector3d anchor = obj.trajectory.Pose(s.t_s) * it->second;
    bool sliding = false;
    Eigen::Vector3d ft = TangentialForce(c, x, anchor, &sliding);
    const Eigen::Matrix3d tangential = Eigen::Matrix3d::Identity() - c.normal * c.normal.transpose();
    if (s.dynamic && bt > 0 && !sliding)
      ft -= bt * (tangential * (s.v_m_s.segment<3>(3 * c.node) - obj.trajectory.PointVelocity(x, s.t_s)));
    f.segment<3>(3 * c.node) += ft;
    if (sink && !sliding) {
      const Eigen::Matrix3d K = kt * tangential;
      const Eigen::Matrix3d D = bt * tangential;
      sink->Add(matrix_->DiagonalSlot(c.node), c.node, c.node, K, s.dynamic ? &D : nullptr);
    }
  }
}

void PseudoFrictionForce::EndStep(const SystemState& s) {
  std::map<std::pair<int, int>, Eigen::Vector3d> next;
  for (const ActiveContact& c : contact_.active_contacts()) {
    const auto& obj = contact_.objects()[size_t(c.object)];
    const Eigen::Isometry3d pose = obj.trajectory.Pose(s.t_s);
    const Eigen::Vector3d x = s.x_m.segment<3>(3 * c.node);
    const auto it = anchors_.find({c.node, c.object});
    if (it == anchors_.end()) {
      next[{c.node, c.object}] = pose.inverse() * x;
      continue;
    }
    Eigen::Vector3d anchor = pose * it->second;
    bool sliding = false;
    const Eigen::Vector3d ft = TangentialForce(c, x, anchor, &sliding);
    if (sliding) {
      // Move the anchor so the spring carries exactly the Coulomb limit.
      const double kt = anisotropy_ * contact_.params().stiffness_N_m;
      if (kt > 0) anchor = x + ft / kt;
    }
    next[{c.node, c.object}] = pose.inverse() * anchor;
  }
  anchors_.swap(next);
}

}  // namespace sedbridge::fem
