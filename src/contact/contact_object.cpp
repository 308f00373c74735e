#include "contact/contact_object.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "sensors/simulated/primitive_object.h"

namespace sedbridge::contact {
namespace {
// A rod long enough to cross the sensor pad (20 mm), not the whole finger.
constexpr double kRodHalfLength_m = 10e-3;

double LeaderMinRadius_mm(sensors::ContactShape shape) {
  return shape == sensors::ContactShape::kSphere ? kLeaderMinSphereRadius_mm : kLeaderMinRodRadius_mm;
}
}  // namespace

geometry::RigidObject ToRigidObject(const sensors::ContactPrimitive& p) {
  return sensors::RigidObjectOf(p, kRodHalfLength_m, LeaderMinRadius_mm(p.shape));
}

std::vector<geometry::RigidObject> ToRigidObjects(const ContactEstimate& estimate) {
  std::vector<geometry::RigidObject> objects = {ToRigidObject(estimate.primitive)};
  if (estimate.two_contacts) objects.push_back(ToRigidObject(estimate.second));
  return objects;
}

LeaderPress PressReconstructed(scene::FingertipCompliance& leader, const ContactEstimate& estimate,
                               const scene::PressToForceOptions& options, const Eigen::Vector2d& tangential_N) {
  LeaderPress out;
  out.result = leader.PressToForce(ToRigidObjects(estimate), estimate.normal_force_N(), options, tangential_N);
  const auto slipped = [&] {
    const scene::PressStatus s = out.result.status;
    return sensors::HasFittedRadius(estimate.primitive.shape) &&
           (s == scene::PressStatus::kNoContact || s == scene::PressStatus::kPatchEdge);
  };
  if (!slipped()) return out;  // the bridge's every scan: no copy of the estimate
  ContactEstimate thicker = estimate;
  for (int k = 0; k < kThickenTries && slipped(); ++k) {
    const double pressed_mm = std::max(thicker.primitive.radius_mm, LeaderMinRadius_mm(thicker.primitive.shape));
    if (!(pressed_mm < kThickenBelow_mm)) break;
    thicker.primitive.radius_mm = kThickenFactor * pressed_mm;
    if (thicker.two_contacts)
      thicker.second.radius_mm = kThickenFactor * std::max(thicker.second.radius_mm, LeaderMinRadius_mm(thicker.second.shape));
    out.thickened_radius_mm = thicker.primitive.radius_mm;
    leader.ResetWarmStart();
    out.result = leader.PressToForce(ToRigidObjects(thicker), estimate.normal_force_N(), options, tangential_N);
    ++out.presses;
  }
  return out;
}

bool PressAnswered(const scene::PressToForceResult& press, const scene::FingertipCompliance& leader,
                   double tolerance) {
  if (press.reached) return true;
  return press.status == scene::PressStatus::kNotConverged && leader.contact().last().converged &&
         std::abs(press.force_N - press.target_force_N) <= tolerance * press.target_force_N;
}

Eigen::Vector2d LeaderTangentialLoad_N(const sensors::ContactPrimitive& p) {
  const Eigen::Vector2d shear(p.shear_x_N, p.shear_y_N);
  const double floor_N = kShearFloor * p.normal_force_N;
  if (!(floor_N > 0) || !shear.allFinite()) return shear;  // no force: nothing is pressed anyway
  const double weight = std::clamp(shear.norm() / floor_N - 1.0, 0.0, 1.0);
  return weight * shear;
}

Eigen::Vector2d LeaderTangentialLoad_N(const ContactEstimate& estimate) {
  sensors::ContactPrimitive whole = estimate.primitive;
  whole.normal_force_N = estimate.normal_force_N();
  return LeaderTangentialLoad_N(whole);
}

scene::FingertipComplianceOptions LeaderComplianceOptions(const std::string& cache_dir, bool face_contact) {
  scene::FingertipComplianceOptions options;
  options.contact.cache_dir = cache_dir;
  options.face_samples = face_contact;
  return options;
}

scene::PressToForceOptions ReconstructedPressOptions() {
  scene::PressToForceOptions options;
  options.relative_tolerance = 1e-3;
  // The leader press's contact law to 1e-5 of its largest force, not the method's 1e-8:
  // the delivered SED moves by at most 5e-5 of its peak over the rig and synthetic fidelity
  // cases (1e-4: 5e-4), while a scan's press takes 2.5-4 outer iterations instead of 5-7
  // (compliance_contact_benchmark BridgePress,
  // docs/lab-notes/2026-11-27-time-per-scan-rounds.md#contact-tolerance).
  options.contact_relative_tolerance = 1e-5;
  return options;
}

}  // namespace sedbridge::contact
