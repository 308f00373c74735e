#pragma once
// A contact primitive (sensors/contact_primitive.h) as a rigid scene object resting on
// the pad plane z = 0 at first touch (pad frame): what the simulated pad and the leader's
// fingertip press.

#include "common/geometry/rigid_object.h"
#include "sensors/contact_primitive.h"

namespace sedbridge::sensors {

/// A punch's edge rounding as pressed [mm]: the rig's edges are rounded by 0.2 mm at most (its
/// README), and the leader's skin carries contact points about 1 mm apart, so any rounding up
/// to that presses alike; 0.2 keeps the box's surface normal continuous.
constexpr double kPunchRounding_mm = 0.2;
/// A punch's height above its face [mm]: only its face touches the pad.
constexpr double kPunchHeight_mm = 10;
/// A corner's cube side [mm]: the scene's box; only its tip touches the pad.
constexpr double kCornerCubeSide_mm = 10;

/// Sphere: SphereSdf centred R above (x, y); cylinder: a rod along (cos yaw, sin yaw, 0)
/// resting on the pad plane, 2 rod_half_length_m long or, a finite rod, length_mm centred
/// on (x, y); flat: the half-space above z = 0; punch: a box kPunchHeight_mm tall with its
/// face (half sizes half_size_mm) on the pad, turned by its yaw, edges rounded
/// kPunchRounding_mm; round punch: a capped cylinder of radius_mm, kPunchHeight_mm tall,
/// standing on its face at (x, y) (its rim sharp, as a scene's cylinder); corner: a sharp cube
/// kCornerCubeSide_mm on a side, a corner straight down on (x, y), turned by its yaw about the
/// vertical. Sphere and rod radii
/// below min_radius_mm are taken as it.
geometry::RigidObject RigidObjectOf(const ContactPrimitive& primitive, double rod_half_length_m,
                                    double min_radius_mm = 0);

}  // namespace sedbridge::sensors
