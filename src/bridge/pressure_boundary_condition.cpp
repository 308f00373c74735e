#include "bridge/pressure_boundary_condition.h"

#include <Eigen/SparseCholesky>
#include <map>
#include <stdexcept>

#include "fem/mesh_topology.h"

namespace sedbridge::bridge {

namespace {

// Lumped-load weights below this fraction of the largest one are dropped [-]: the consistent
// mass solve leaves round-off fill-in everywhere, which would only slow every step's product.
constexpr double kDropWeightRatio = 1e-12;

}  // namespace

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
  const SkinNodes nodes = SkinNodesOf(scene);
  field_ = BuildTractionWeights(profile, registration, nodes, options);
  applied_ = field_.W;
  if (options.nodal_load == NodalLoad::kLumped && field_.W.nonZeros() > 0) {
    // M: consistent-load matrix of the skin triangles (SurfaceTractionForce's formula).
    const std::vector<int>& ids = scene.traction()->nodes();
    std::map<int, int> local;
    for (size_t k = 0; k < ids.size(); ++k) local[ids[k]] = static_cast<int>(k);
    const Eigen::Matrix3Xd& X = scene.model().soft.rest_positions_m;
    std::vector<Eigen::Triplet<double>> m;
    for (const auto& tri : scene.model().skin_triangles) {
      const double A = 0.5 * (X.col(tri[1]) - X.col(tri[0])).cross(X.col(tri[2]) - X.col(tri[0])).norm();
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) m.emplace_back(local.at(tri[a]), local.at(tri[b]), A / 12.0 * (a == b ? 2 : 1));
    }
    const Eigen::Index n = static_cast<Eigen::Index>(ids.size());
    Eigen::SparseMatrix<double> M(n, n);
    M.setFromTriplets(m.begin(), m.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(M);
    if (ldlt.info() != Eigen::Success) throw std::runtime_error("consistent-load matrix of the skin is singular");
    const Eigen::MatrixXd rhs = nodes.area_m2.asDiagonal() * Eigen::MatrixXd(field_.W);
    const Eigen::MatrixXd X_lumped = ldlt.solve(rhs);
    const double tiny = kDropWeightRatio * X_lumped.cwiseAbs().maxCoeff();
    applied_ = X_lumped.sparseView(1.0, tiny);
    applied_.makeCompressed();
  }
  traction_pad_ = Eigen::Matrix3Xd::Zero(3, applied_.rows());
  traction_model_ = traction_pad_;
}

const Eigen::Matrix3Xd& PressureBoundaryCondition::Apply(const TaxelValues& values) {
  const Eigen::Index n = applied_.cols();
  if (static_cast<Eigen::Index>(values.pressure_Pa.size()) != n)
    throw std::invalid_argument("taxel count does not match the boundary condition");
  tmp_in_ = Eigen::Map<const Eigen::VectorXd>(values.pressure_Pa.data(), n);
  tmp_out_.noalias() = applied_ * tmp_in_;
  traction_pad_.row(2) = -tmp_out_.transpose();
  if (static_cast<Eigen::Index>(values.shear_x_Pa.size()) == n && static_cast<Eigen::Index>(values.shear_y_Pa.size()) == n) {
    tmp_in_ = Eigen::Map<const Eigen::VectorXd>(values.shear_x_Pa.data(), n);
    tmp_out_.noalias() = applied_ * tmp_in_;
    traction_pad_.row(0) = tmp_out_.transpose();
    tmp_in_ = Eigen::Map<const Eigen::VectorXd>(values.shear_y_Pa.data(), n);
    tmp_out_.noalias() = applied_ * tmp_in_;
    traction_pad_.row(1) = tmp_out_.transpose();
  } else {
    traction_pad_.topRows(2).setZero();
  }
  traction_model_.noalias() = model_from_pad_rotation_ * traction_pad_;
  return traction_model_;
}

}  // namespace sedbridge::bridge
