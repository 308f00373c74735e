#pragma once
// The sensor-driven load on one fingertip scene: taxel values -> traction at every node of
// the scene's SurfaceTractionForce (model frame). The interpolation map W (traction_field.h)
// is built ONCE from the scene's rest skin; a step is then one sparse product per axis and a
// rotation into the model frame.
//
//   PressureBoundaryCondition bc(scene, profile, registration);
//   scene.traction()->SetNodalTraction(bc.Apply(values));   // values: TaxelValues
//
// W is exposed (applied_weights()) so that a reduced FE path can fold it into its own operator.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "bridge/pad_registration.h"
#include "bridge/taxel_values.h"
#include "bridge/traction_field.h"
#include "scene/fingertip_scene.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::bridge {

/// Skin nodes of a scene's traction term in the pad frame (positions, outward normals,
/// consistent-load areas), in the order of traction()->nodes().
SkinNodes SkinNodesOf(const scene::FingertipScene& scene);

class PressureBoundaryCondition {
 public:
  /// `scene` must have surface_traction: true (throws std::invalid_argument otherwise) and
  /// must outlive this object.
  PressureBoundaryCondition(const scene::FingertipScene& scene, const sensors::SensorProfile& profile,
                            const PadRegistration& registration, const TractionFieldOptions& options = {});

  /// Traction at each traction()->nodes() entry [Pa], model frame, 3 x #nodes. `values`
  /// must have the profile's taxel count (shear may be empty). The result is a member
  /// buffer, valid until the next call.
  const Eigen::Matrix3Xd& Apply(const TaxelValues& values);

  /// The map actually applied (with the lumped-load compensation when options.nodal_load is
  /// kLumped), #nodes x #taxels. The same matrix serves all three axes: node traction along
  /// each pad axis = applied_weights() * the taxel values along that axis (normal: inward
  /// pressure, so the traction is its negative along z_pad).
  const Eigen::SparseMatrix<double, Eigen::RowMajor>& applied_weights() const { return applied_; }
  /// The interpolation (before any lumped-load compensation).
  const TractionWeights& field() const { return field_; }
  /// Last Apply() in the pad frame: rows shear x, shear y, normal (outward +), 3 x #nodes.
  const Eigen::Matrix3Xd& traction_pad_Pa() const { return traction_pad_; }
  int num_nodes() const { return static_cast<int>(traction_pad_.cols()); }

 private:
  Eigen::Matrix3d model_from_pad_rotation_;
  TractionWeights field_;                              // the interpolation (traction_field.h)
  Eigen::SparseMatrix<double, Eigen::RowMajor> applied_;  // what Apply() multiplies by
  Eigen::Matrix3Xd traction_pad_, traction_model_;
  Eigen::VectorXd tmp_in_, tmp_out_;
};

}  // namespace sedbridge::bridge
