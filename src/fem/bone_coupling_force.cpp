#include "fem/bone_coupling_force.h"

namespace sedbridge::fem {

BoneCouplingForce::BoneCouplingForce(const Eigen::Matrix3Xd& rest, std::vector<int> nodes,
                                     std::vector<Eigen::Vector3d> normals, SpringDamperParams params,
                                     std::shared_ptr<const geometry::Trajectory> motion)
    : nodes_(std::move(nodes)), params_(params), motion_(std::move(motion)) {
  for (size_t k = 0; k < nodes_.size(); ++k) {
    rest_.push_back(rest.col(nodes_[k]));
    Eigen::Matrix3d shape = Eigen::Matrix3d::Identity();
    if (params_.anisotropy != 1.0 && k < normals.size() && normals[k].norm() > 0) {
      const Eigen::Vector3d n = normals[k].normalized();
      shape = n * n.transpose() + params_.anisotropy * (Eigen::Matrix3d::Identity() - n * n.transpose());
    }
    stiffness_.push_back(shape);
  }
}

void BoneCouplingForce::BindMatrix(const SystemMatrix& matrix) {
  slots_.clear();
  for (int n : nodes_) slots_.push_back(matrix.DiagonalSlot(n));
}

Eigen::Vector3d BoneCouplingForce::Anchor(size_t k, double t) const {
  if (!motion_) return rest_[k];
  return motion_->Pose(t) * (motion_->Pose(0).inverse() * rest_[k]);
}

void BoneCouplingForce::AddForce(const SystemState& s, Eigen::VectorXd& f, JacobianSink* sink) {
  const Eigen::Isometry3d motion =
      motion_ ? Eigen::Isometry3d(motion_->Pose(s.t_s) * motion_->Pose(0).inverse())
              : Eigen::Isometry3d::Identity();
  for (int k = 0; k < int(nodes_.size()); ++k) {
    const int i = nodes_[size_t(k)];
    const Eigen::Matrix3d R = motion.linear();
    const Eigen::Matrix3d shape = R * stiffness_[size_t(k)] * R.transpose();
    const Eigen::Matrix3d K = params_.stiffness_N_m * shape;
    const Eigen::Vector3d anchor = motion * rest_[size_t(k)];
    Eigen::Vector3d force = -K * (s.x_m.segment<3>(3 * i) - anchor);
    const Eigen::Matrix3d D = params_.damping_N_s_m * shape;
    if (s.dynamic && params_.damping_N_s_m > 0) {
      const Eigen::Vector3d v_anchor = motion_ ? motion_->PointVelocity(anchor, s.t_s) : Eigen::Vector3d::Zero();
      force -= D * (s.v_m_s.segment<3>(3 * i) - v_anchor);
    }
    f.segment<3>(3 * i) += force;
    if (sink) sink->Add(slots_[size_t(k)], i, i, K, s.dynamic ? &D : nullptr);
  }
}

double BoneCouplingForce::PotentialEnergy(const SystemState& s) const {
  double e = 0;
  for (size_t k = 0; k < nodes_.size(); ++k) {
    const Eigen::Vector3d d = s.x_m.segment<3>(3 * nodes_[k]) - Anchor(k, s.t_s);
    e += 0.5 * params_.stiffness_N_m * d.dot(stiffness_[k] * d);
  }
  return e;
}

}  // namespace sedbridge::fem
