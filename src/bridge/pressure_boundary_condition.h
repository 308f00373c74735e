#pragma once
// The sensor-driven load on one fingertip scene: taxel values -> traction at every node of
// the scene's SurfaceTractionForce (model frame). The interpolation map W (traction_field.h)
// is built ONCE from the scene's rest skin; a step is then one sparse product per axis and a
// rotation into the model frame.
//
//   PressureBoundaryCondition bc(scene, profile, registration);
//   scene.traction()->SetNodalTraction(bc.Apply(values));   // values: TaxelValues
//
// W is exposed (weights()) so that a reduced FE path can fold it into its own operator.

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
  enum Axis { kShearX = 0, kShearY = 1, kNormal = 2 };

  /// `scene` must have surface_traction: true (throws std::invalid_argument otherwise) and
  /// must outlive this object.
  PressureBoundaryCondition(const scene::FingertipScene& scene, const sensors::SensorProfile& profile,
                            const PadRegistration& registration, const TractionFieldOptions& options = {});

  /// Traction at each traction()->nodes() entry [Pa], model frame, 3 x #nodes. `values`
  /// must have the profile's taxel count (shear may be empty). The result is a member
  /// buffer, valid until the next call.
  const Eigen::Matrix3Xd& Apply(const TaxelValues& values);

  /// Node traction along `axis` (pad frame) = weights(axis) * taxel values along that axis
  /// (normal: inward pressure, the traction is its negative along z_pad). One matrix serves
  /// all three axes here; the accessor is per axis so a later kernel may differ.
  const Eigen::SparseMatrix<double, Eigen::RowMajor>& weights(Axis axis) const { return field_.W; }
  const TractionWeights& field() const { return field_; }
  /// Last Apply() in the pad frame: rows shear x, shear y, normal (outward +), 3 x #nodes.
  const Eigen::Matrix3Xd& traction_pad_Pa() const { return traction_pad_; }
  int num_nodes() const { return static_cast<int>(traction_pad_.cols()); }

 private:
  Eigen::Matrix3d model_from_pad_rotation_;
  TractionWeights field_;
  Eigen::Matrix3Xd traction_pad_, traction_model_;
  Eigen::VectorXd tmp_in_, tmp_out_;
};

}  // namespace sedbridge::bridge
