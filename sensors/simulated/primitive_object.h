#pragma once
// A contact primitive (sensors/contact_primitive.h) as a rigid scene object resting on
// the pad plane z = 0 at first touch (pad frame): what the simulated pad and the leader's
// fingertip press.

#include "common/geometry/rigid_object.h"
#include "sensors/contact_primitive.h"

namespace sedbridge::sensors {

/// Sphere: SphereSdf centred R above (x, y); cylinder: a rod along (cos yaw, sin yaw, 0)
/// resting on the pad plane, 2 rod_half_length_m long or, a finite rod, length_mm centred
/// on (x, y); flat: the half-space above z = 0. Radii below min_radius_mm are taken as it.
geometry::RigidObject RigidObjectOf(const ContactPrimitive& primitive, double rod_half_length_m,
                                    double min_radius_mm = 0);

}  // namespace sedbridge::sensors
