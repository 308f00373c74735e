#pragma once
// A reconstructed (or known) contact primitive as a rigid object for the leader's fingertip
// model: the same shape, posed in the leader's pad frame at first touch (lowest point on
// the pad plane z = 0), ready for scene::FingertipCompliance::PressToForce.

#include "common/geometry/rigid_object.h"
#include "scene/fingertip_compliance.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::bridge {

/// Sphere: SphereSdf centred R above (x, y); cylinder: an infinite rod along (cos yaw,
/// sin yaw, 0) resting on the pad plane; flat: the half-space above z = 0.
geometry::RigidObject ToRigidObject(const sensors::ContactPrimitive& primitive);

/// Options of the leader press of a reconstructed contact (bridge and fidelity benchmark):
/// the force is matched to 1e-3 relative, not PressToForce's default 1e-6. The target is
/// the reconstruction's force estimate, uncertain by about 1 % (2-count noise over the
/// taxels), so the last digits cost contact solves (a third of them at hold) and buy
/// nothing; the SED then differs from the 1e-6 answer by about 1e-3 relative.
scene::PressToForceOptions ReconstructedPressOptions();

/// Whether a leader press answered: it reached the force, or its root find flagged a trial
/// solve that did not converge while the last solve converged within `tolerance` (relative)
/// of the target — the state left behind is then the answer.
bool PressAnswered(const scene::PressToForceResult& press, const scene::FingertipCompliance& leader,
                   double tolerance = 0.01);

}  // namespace sedbridge::bridge
