#pragma once
// A reconstructed (or known) contact primitive as a rigid object for the leader's fingertip
// model: the same shape, posed in the leader's pad frame at first touch (lowest point on
// the pad plane z = 0), ready for scene::FingertipCompliance::PressToForce.

#include <vector>

#include "bridge/bridge_config.h"
#include "bridge/contact_reconstruction.h"
#include "common/geometry/rigid_object.h"
#include "scene/fingertip_compliance.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::bridge {

/// Thinnest sphere or rod pressed on the leader [mm]. The leader's skin has contact points
/// about 1.5 mm apart (nodes and face centroids, §11 of docs/bridge-fidelity.md): a thinner
/// object slips between them (no contact, or a press that cannot reach its force inside the
/// pad), and its SED on that mesh is a 0.5 mm object's. The reconstruction reads sharp
/// features (a box edge, thin rods on an elastic half-space pad) down to its 0.3 mm bound.
constexpr double kLeaderMinRadius_mm = 0.5;

/// Sphere: SphereSdf centred R above (x, y); cylinder: a rod along (cos yaw, sin yaw, 0)
/// resting on the pad plane, 20 mm long (across the pad) or, a finite rod, length_mm
/// centred on (x, y); flat: the half-space above z = 0. Radii below kLeaderMinRadius_mm are
/// pressed as that.
geometry::RigidObject ToRigidObject(const sensors::ContactPrimitive& primitive);
/// The objects of an estimate: its primitive, and a pair's second sphere. Both rest on the
/// pad plane at first touch and are pressed together, as one rigid pair, to the total force
/// (the leader's mechanics share it out).
std::vector<geometry::RigidObject> ToRigidObjects(const ContactEstimate& estimate);

/// Options of the leader press of a reconstructed contact (bridge and fidelity benchmark):
/// the force is matched to 1e-3 relative, not PressToForce's default 1e-6. The target is
/// the reconstruction's force estimate, uncertain by about 1 % (2-count noise over the
/// taxels), so the last digits cost contact solves (a third of them at hold) and buy
/// nothing; the SED then differs from the 1e-6 answer by about 1e-3 relative.
scene::PressToForceOptions ReconstructedPressOptions();
/// The same with the config's fe.contact_tolerance as its contact tolerance.
scene::PressToForceOptions ReconstructedPressOptions(const BridgeConfig& config);
/// The reconstruction of fe.step contact as a config sets it (fe.two_contacts,
/// fe.finite_rods): one place for the bridge (MakeFeStep) and the fidelity benchmark.
ReconstructionOptions ReconstructionOptionsOf(const BridgeConfig& config);

/// The leader's fingertip for reconstructed contacts (bridge and fidelity benchmark), its
/// precompute cached in `cache_dir` ("" = none). face_contact (bridge key fe.face_contact,
/// default true): contact points on the skin faces too
/// (scene::FingertipComplianceOptions::face_samples), so that a rod thinner than the
/// skin-node spacing is caught and a thin rod's press is not balanced on one row of nodes;
/// it costs about twice the leader press's time (docs/bridge-fidelity.md §11).
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

}  // namespace sedbridge::bridge
