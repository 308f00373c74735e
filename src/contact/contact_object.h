#pragma once
// A reconstructed (or known) contact primitive as a rigid object for the leader's fingertip
// model: the same shape, posed in the leader's pad frame at first touch (lowest point on
// the pad plane z = 0), ready for scene::FingertipCompliance::PressToForce.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "contact/contact_estimate.h"
#include "common/geometry/rigid_object.h"
#include "scene/fingertip_compliance.h"
#include "sensors/contact_primitive.h"

namespace sedbridge::contact {

/// Thinnest rod and sphere pressed on the leader [mm]. The leader's skin carries contact points
/// about 1.5 mm apart (nodes and face centroids,
/// docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s11): a thinner object slips between
/// them (no contact, or a press that leaves the patch before reaching its force), and its SED
/// on that mesh is not a thin object's anyway. Measured on model B (test
/// ContactObject.TheLeaderHoldsWhatItsMinimumRadiiPress, 2026-11-26): a sphere of 0.8 mm
/// pressed to 0.2 N is held at each of 15 places (0.7 mm: 7 of 45 places slip); a rod of 0.5 mm
/// pressed to 1.2 N slips at 13 of 12 yaws x 3 places (0.65 mm: none). Where a 0.5 mm rod
/// holds, its ridge can still break into a spot or two where the contact points happen to lie
/// along it (of 324 poses and forces, 62 presses of a 0.5 mm rod failed and 5 peaked at 1.8-3.6
/// times the 1 mm rod's SED; at 0.6 mm, 3 and none:
/// docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s16), so rods are pressed at 0.6 mm at
/// least (test ContactObject.ThinRodKeepsOneRidgeOnTheLeader), and a press that slips is tried
/// thicker (PressReconstructed). More force needs a thicker object (a 1 mm sphere slips
/// everywhere at 1 N, 1.5 mm holds). The reconstruction reads sharp features (a box edge, thin
/// rods on an elastic pad) down to its 0.3 mm bound.
constexpr double kLeaderMinRodRadius_mm = 0.6;
constexpr double kLeaderMinSphereRadius_mm = 0.8;

/// Sphere: SphereSdf centred R above (x, y); cylinder: a rod along (cos yaw, sin yaw, 0)
/// resting on the pad plane, 20 mm long (across the pad) or, a finite rod, length_mm
/// centred on (x, y); flat: the half-space above z = 0. Rods thinner than
/// kLeaderMinRodRadius_mm and spheres thinner than kLeaderMinSphereRadius_mm are pressed
/// at that radius.
geometry::RigidObject ToRigidObject(const sensors::ContactPrimitive& primitive);
/// The objects of an estimate: its primitive, and a pair's second sphere. Both rest on the
/// pad plane at first touch and are pressed together, as one rigid pair, to the total force
/// (the leader's mechanics share it out).
std::vector<geometry::RigidObject> ToRigidObjects(const ContactEstimate& estimate);

/// The leader press of a reconstructed contact: ToRigidObjects(estimate) pressed to the
/// estimate's force with `tangential_N`. A sphere or rod the leader's contact points cannot
/// hold at that force (more force needs a deeper press, and the skin's points spread around a
/// thin object: a 1 mm sphere slips through at 1 N, where 1.5 mm holds) ends in no contact or
/// at the patch's edge; then, while thinner than kThickenBelow_mm, it is pressed again
/// kThickenFactor thicker, at most kThickenTries times: the SED of the thinnest object the
/// leader holds, not the pressure map's.
struct LeaderPress {
  scene::PressToForceResult result;
  double thickened_radius_mm = 0;  ///< > 0: the radius it was pressed at instead
  int presses = 1;          ///< PressToForce calls (1 + retries)
};
constexpr double kThickenBelow_mm = 2.0;
constexpr double kThickenFactor = 1.5;
constexpr int kThickenTries = 2;
LeaderPress PressReconstructed(scene::FingertipCompliance& leader, const ContactEstimate& estimate,
                               const scene::PressToForceOptions& options, const Eigen::Vector2d& tangential_N);

/// Options of the leader press of a reconstructed contact (bridge and fidelity benchmark):
/// the force is matched to 1e-3 relative, not PressToForce's default 1e-6. The target is
/// the reconstruction's force estimate, uncertain by about 1 % (2-count noise over the
/// taxels), so the last digits cost contact solves (a third of them at hold) and buy
/// nothing; the SED then differs from the 1e-6 answer by about 1e-3 relative.
scene::PressToForceOptions ReconstructedPressOptions();
/// The leader's fingertip for reconstructed contacts (bridge and fidelity benchmark), its
/// precompute cached in `cache_dir` ("" = none). face_contact (bridge key fe.face_contact,
/// default true): contact points on the skin faces too
/// (scene::FingertipComplianceOptions::face_samples), so that a rod thinner than the
/// skin-node spacing is caught and a thin rod's press is not balanced on one row of nodes;
/// it costs about twice the leader press's time (docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s11).
scene::FingertipComplianceOptions LeaderComplianceOptions(const std::string& cache_dir, bool face_contact = true);

/// The tangential load [N, pad frame] the leader is pressed with for a reconstructed contact:
/// the estimated shear, faded out where it is within the sensor's normal-to-shear crosstalk.
/// Weight 0 while |shear| <= kShearFloor * normal force, 1 from twice that, linear between
/// (continuous in the estimate). The rig's purely normal presses leave 0.0-0.5 % of the
/// normal force in the estimated shear, its stroking presses 25-30 %; and a leader press of
/// a thin rod is not continuous in a tangential load that small (press_13: 0.1 % of the
/// normal force takes 6 contact nodes to 10 and moves the SED peak by 1.8 mm,
/// docs/bridge-fidelity.md), so the crosstalk must not reach the leader.
Eigen::Vector2d LeaderTangentialLoad_N(const sensors::ContactPrimitive& primitive);
/// Same for an estimate: its tangential force against its whole normal force (a pair's both).
Eigen::Vector2d LeaderTangentialLoad_N(const ContactEstimate& estimate);
/// Fraction of the normal force below which estimated shear is crosstalk (see above).
inline constexpr double kShearFloor = 0.01;

/// Whether a leader press answered: it reached the force, or its root find flagged a trial
/// solve that did not converge while the last solve converged within `tolerance` (relative)
/// of the target — the state left behind is then the answer.
bool PressAnswered(const scene::PressToForceResult& press, const scene::FingertipCompliance& leader,
                   double tolerance = 0.01);

}  // namespace sedbridge::contact
