#pragma once
// A reconstructed (or known) contact primitive as a rigid object for the leader's fingertip
// model: the same shape, posed in the leader's pad frame at first touch (lowest point on
// the pad plane z = 0), ready for scene::FingertipCompliance::PressToForce.

#include "geometry/rigid_object.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::bridge {

/// Sphere: SphereSdf centred R above (x, y); cylinder: an infinite rod along (cos yaw,
/// sin yaw, 0) resting on the pad plane; flat: the half-space above z = 0.
geometry::RigidObject ToRigidObject(const sensors::ContactPrimitive& primitive);

}  // namespace sedbridge::bridge
