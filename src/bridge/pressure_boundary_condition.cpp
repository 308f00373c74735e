#include "bridge/pressure_boundary_condition.h"

#include <stdexcept>

#include "fem/mesh_topology.h"

namespace sedbridge::bridge {

SkinNodes SkinNodesOf(const scene::FingertipScene& scene) {
  const fem::SurfaceTractionForce* traction = scene.traction();
  if (!traction) throw std::invalid_argument("the scene has no surface_traction term");
  const model::FingertipModel& m = scene.model();
  const std::vector<int>& ids = traction->nodes();
  const int n = static_cast<int>(ids.size());
  const std::vector<Eigen::Vector3d> normals = fem::VertexNormals(m.skin_triangles, m.soft.rest_positions_m, ids);
  const Eigen::Matrix3d R_pad_from_model = m.pad_frame.model_from_pad.linear().transpose();
  SkinNodes out;
  out.position_pad_mm.resize(3, n);
  out.normal_pad.resize(3, n);
  out.area_m2.resize(n);
  for (int k = 0; k < n; ++k) {
    out.position_pad_mm.col(k) = m.pad_frame.ToPad(traction->node_rest_positions_m().col(k)) * 1e3;
    out.normal_pad.col(k) = R_pad_from_model * normals[size_t(k)];
    out.area_m2[k] = scene.skin_node_area_m2()[ids[size_t(k)]];
  }
  return out;
}

PressureBoundaryCondition::PressureBoundaryCondition(const scene::FingertipScene& scene,
                                                     const sensors::SensorProfile& profile,
                                                     const PadRegistration& registration,
                                                     const TractionFieldOptions& options)
    : model_from_pad_rotation_(scene.model().pad_frame.model_from_pad.linear()) {
  field_ = BuildTractionWeights(profile, registration, SkinNodesOf(scene), options);
  traction_pad_ = Eigen::Matrix3Xd::Zero(3, field_.W.rows());
  traction_model_ = traction_pad_;
}

const Eigen::Matrix3Xd& PressureBoundaryCondition::Apply(const TaxelValues& values) {
  const Eigen::Index n = field_.W.cols();
  if (static_cast<Eigen::Index>(values.pressure_Pa.size()) != n)
    throw std::invalid_argument("taxel count does not match the boundary condition");
  tmp_in_ = Eigen::Map<const Eigen::VectorXd>(values.pressure_Pa.data(), n);
  tmp_out_.noalias() = field_.W * tmp_in_;
  traction_pad_.row(2) = -tmp_out_.transpose();
  if (static_cast<Eigen::Index>(values.shear_x_Pa.size()) == n && static_cast<Eigen::Index>(values.shear_y_Pa.size()) == n) {
    tmp_in_ = Eigen::Map<const Eigen::VectorXd>(values.shear_x_Pa.data(), n);
    tmp_out_.noalias() = field_.W * tmp_in_;
    traction_pad_.row(0) = tmp_out_.transpose();
    tmp_in_ = Eigen::Map<const Eigen::VectorXd>(values.shear_y_Pa.data(), n);
    tmp_out_.noalias() = field_.W * tmp_in_;
    traction_pad_.row(1) = tmp_out_.transpose();
  } else {
    traction_pad_.topRows(2).setZero();
  }
  traction_model_.noalias() = model_from_pad_rotation_ * traction_pad_;
  return traction_model_;
}

}  // namespace sedbridge::bridge
