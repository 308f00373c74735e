#include "fem/penalty_contact_force.h"

#include <Eigen/Dense>
namespace sedbridge::fem {

PenaltyContactForce::PenaltyContactForce(std::vector<int> nodes, std::vector<geometry::RigidObject> objects,
                                         ContactParams params)
    : nodes_(std::move(nodes)), objects_(std::move(objects)), params_(params) {}

void PenaltyContactForce::BindMatrix(const SystemMatrix& matrix) {
  slots_.clear();
  for (int n : nodes_) slots_.push_back(matrix.DiagonalSlot(n));
}

void PenaltyContactForce::AddForce(const SystemState& s, Eigen::VectorXd& f, JacobianSink* sink) {
  active_.clear();
  const double k = params_.stiffness_N_m, b = params_.damping_N_s_m;
  for (size_t c = 0; c < nodes_.size(); ++c) {
    const int i = nodes_[c];
    const Eigen::Vector3d x = s.x_m.segment<3>(3 * i);
    for (int o = 0; o < int(objects_.size()); ++o) {
      const geometry::SdfSample sdf = objects_[size_t(o)].Evaluate(x, s.t_s);
      if (!(sdf.distance_m < 0)) continue;
      const Eigen::Vector3d& n = sdf.normal;
      const double spring = -k * sdf.distance_m;
      double normal_force = spring;
      bool damper_active = false;
      if (s.dynamic && b > 0) {
        const Eigen::Vector3d v_rel =
            s.v_m_s.segment<3>(3 * i) - objects_[size_t(o)].trajectory.PointVelocity(x, s.t_s);
        normal_force -= b * n.dot(v_rel);
        damper_active = normal_force > 0;
      }
      normal_force = std::max(normal_force, 0.0);  // a penalty never glues skin to the object
      f.segment<3>(3 * i) += normal_force * n;
      active_.push_back({i, o, n, -sdf.distance_m, spring, normal_force});
      if (sink) {
        const Eigen::Matrix3d nn = n * n.transpose();
        const Eigen::Matrix3d K = k * nn;
        const Eigen::Matrix3d D = b * nn;
        sink->Add(slots_[c], i, i, K, damper_active ? &D : nullptr);
      }
    }
  }
}

double PenaltyContactForce::PotentialEnergy(const SystemState& s) const {
  double e = 0;
  for (int i : nodes_)
    for (const auto& obj : objects_) {
      const double d = obj.Evaluate(s.x_m.segment<3>(3 * i), s.t_s).distance_m;
      if (d < 0) e += 0.5 * params_.stiffness_N_m * d * d;
    }
  return e;
}

Eigen::Vector3d PenaltyContactForce::TotalSpringForce() const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& c : active_) sum += c.spring_force_N * c.normal;
  return sum;
}

double PenaltyContactForce::TotalSpringForceMagnitude() const { return TotalSpringForce().norm(); }

void PenaltyContactForce::AppendStiffNodes(std::vector<int>& nodes) const {
  for (const auto& c : active_) nodes.push_back(c.node);
}

}  // namespace sedbridge::fem
