#pragma once
// Contact on a fingertip model by the compliance method (fem/compliance_contact.h), in the
// pad frame: the candidate contact nodes are the skin facing the pad, the SED is the
// Merkel layer's (same vertex order as scene::MerkelLayer and the bridge's
// FeStep::merkel_rest_pad_mm). For a linear, quasi-static scene with the bone fixed it
// gives the full FE penalty-contact answer at haptic rates; PressToForce finds the
// indentation at which objects reach a given force (the contact stage's leader press).
//
// Units: SI inside; names carry the unit at the boundaries (depth_mm, force_N, sed_Pa).
//
// Use (contact reconstruction: one hypothesis pressed to the force the sensor measured):
//   const model::FingertipModel model = model::LoadFingertipModel("B");
//   scene::FingertipComplianceOptions options;
//   options.contact.cache_dir = "out/cache";          // precompute once, then load (docs/performance.md)
//   scene::FingertipCompliance fingertip(model, options);
//   geometry::RigidObject sphere{"s", std::make_shared<geometry::SphereSdf>(8e-3),
//       geometry::Trajectory(Eigen::Isometry3d(Eigen::Translation3d(0, 1e-3, 8e-3)))};  // pad frame, touching
//   const scene::PressToForceResult r = fingertip.PressToForce({sphere}, 1.0 /*N*/, {}, shear_pad_N);
//   if (r.reached) use(fingertip.sed_Pa(), fingertip.merkel_rest_pad_mm());  // else r.status says why
// or, with poses already known, fingertip.Step(objects_pad, t_s, shear_pad_N) each scan.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "fem/bone_coupling_force.h"
#include "fem/compliance_contact.h"
#include "common/geometry/rigid_object.h"
#include "model/fingertip_model.h"
#include "scene/scene_description.h"

namespace sedbridge::scene {

struct FingertipComplianceOptions {
  /// Candidate nodes: skin whose outward normal . z_pad >= min_facing and that lies at
  /// most max_depth_mm below the pad-frame origin (as config/bridge traction's keys).
  double min_facing = 0.5;
  double max_depth_mm = 6.0;
  /// Bone coupling (the model's support; paper: k 200 N/m, isotropic).
  fem::SpringDamperParams bone;
  /// k_contact [N/m], iteration control, cache folder (fem::ComplianceContactOptions).
  fem::ComplianceContactOptions contact;
  /// Face contact: the centroid of every skin triangle of the candidate patch is a contact
  /// point too (fem::ContactSample), so that objects narrower than the skin-node spacing
  /// (about 1.5 mm on B: thin rods, edges) are caught between nodes. k_contact is then
  /// shared: each point gets k * #nodes / #points, so a flat press keeps the patch's total
  /// stiffness. false: node contact (the paper's; what the full FE solve does).
  bool face_samples = false;
};

/// Options for a scene that asks for the compliance method; throws std::invalid_argument
/// naming what the scene has that the method cannot do (corotational, backward Euler, a
/// tracked bone, friction with coulomb_mu > 0, surface traction, no bone, full_sed).
FingertipComplianceOptions ComplianceOptionsFromScene(const SceneDescription& scene);

enum class PressStatus {
  kReached,       ///< force within tolerance of the target
  kMaxDepth,      ///< max_indentation_mm reached below the target force
  kPatchEdge,     ///< contact reaches the edge of the candidate patch (or touches skin that
                  ///< is not a candidate): the answer is not the full FE's; move the object
  kNoContact,     ///< nothing touches up to max_indentation_mm (object off the pad)
  kAboveTarget,   ///< already above the target at indentation 0 (objects start inside the skin)
  kInvalidInput,  ///< target not finite and > 0, no objects, non-finite pose
  kNotConverged,  ///< the root find or a contact solve ran out of iterations
};
const char* ToString(PressStatus status);

struct PressToForceOptions {
  double relative_tolerance = 1e-6;   ///< |force - target| <= this * target
  double max_indentation_mm = 5.0;    ///< deepest push tried
  /// Largest indentation change between two contact solves [mm]: the SDF is evaluated at
  /// the displaced nodes, so a jump deeper than a thin object's radius lets skin nodes
  /// tunnel through it (a 1 mm rod pushed from 1 to 2 mm in one solve loses its force).
  double max_step_mm = 0.2;
  int max_iterations = 60;            ///< contact solves in one call
  /// First try one force-controlled contact solve (fem::ComplianceContact::StepToForce:
  /// the indentation found with the contact forces); if it does not converge, or the
  /// objects start inside the skin, or the contact has friction springs, the root find over
  /// indentation-controlled solves answers. false: the root find only.
  bool force_control = true;
  /// The contact solves' own tolerance for this call (fem::ComplianceContactOptions::
  /// relative_tolerance: the penalty law k * depth to this fraction of the largest contact
  /// force); 0 = the contact's configured one (1e-8 by default, what makes the method equal
  /// the full FE to 1e-6). Looser is faster: fewer outer iterations per solve.
  double contact_relative_tolerance = 0;
};

struct PressToForceResult {
  PressStatus status = PressStatus::kInvalidInput;
  bool reached = false;          ///< status == kReached
  double target_force_N = 0;
  double force_N = 0;            ///< normal force reached (along -z_pad, on the skin)
  double indentation_mm = 0;     ///< push along -z_pad from the poses at first touch
  int iterations = 0;            ///< contact solves used
  bool force_controlled = false; ///< answered by one force-controlled solve (no root find)
  int active_nodes = 0;          ///< skin nodes in contact at the answer
  std::string message;           ///< why, when not reached
};

class FingertipCompliance {
 public:
  /// Builds (or loads from options.contact.cache_dir) the precompute for `model`, which
  /// must outlive this object. The precompute dominates startup without the cache (times:
  /// docs/performance.md, "Contact by the compliance method").
  FingertipCompliance(const model::FingertipModel& model, FingertipComplianceOptions options = {});

  /// Contact with objects posed in the pad frame at time t_s, plus a total tangential load
  /// [N] along pad x and y spread over the contacts in proportion to their normal force
  /// (a stroking follower sensor measures shear). Warm-started from the last call.
  /// Forgets the contact state (next press starts from no contact at indentation 0).
  void ResetWarmStart();

  const fem::ComplianceStepResult& Step(const std::vector<geometry::RigidObject>& objects_pad_frame,
                                        double t_s = 0.0, const Eigen::Vector2d& tangential_pad_N = Eigen::Vector2d::Zero());
  /// Normal force of the last step: the spring forces' component along -z_pad [N].
  double normal_force_N() const;
  /// An external load held on the contact points [N, pad frame], one column per contact
  /// point (contact().num_samples(): the candidate nodes, then the face samples), applied by
  /// every Step until changed or cleared (fem::ComplianceContact::SetSampleLoads: a display's
  /// suction). PressToForce refuses while one is held (its search takes no force at no
  /// contact). Throws std::invalid_argument for the wrong size or a non-finite entry.
  void SetSampleLoads(const Eigen::Matrix3Xd& force_pad_N);
  void ClearSampleLoads() { contact_->ClearSampleLoads(); }

  /// Pushes the objects (pad-frame poses at first touch, their trajectory at t = 0) along
  /// -z_pad until their total normal force is target_force_N; the state of the last step
  /// (SED, contacts) is then the answer's. Never throws for bad input: see status.
  /// Warm-started from the last call's indentation. With friction springs the anchors of
  /// earlier steps are dropped first (frictionless press: nothing is anchored yet).
  PressToForceResult PressToForce(const std::vector<geometry::RigidObject>& objects_pad_at_touch,
                                  double target_force_N, const PressToForceOptions& options = {},
                                  const Eigen::Vector2d& tangential_pad_N = Eigen::Vector2d::Zero());

  /// Merkel SED of the last step [Pa], per vertex in model.merkel_nodes order.
  const Eigen::VectorXd& sed_Pa() const { return contact_->last().sed_Pa; }
  /// Merkel vertex rest positions in the pad frame [mm], 3 x #vertices.
  const Eigen::Matrix3Xd& merkel_rest_pad_mm() const { return merkel_rest_pad_mm_; }
  /// 1 for candidate nodes on the edge of the patch (next to non-candidate skin).
  const std::vector<char>& candidate_on_edge() const { return on_edge_; }

  const fem::ComplianceContact& contact() const { return *contact_; }
  fem::ComplianceContact& contact() { return *contact_; }
  const model::FingertipModel& model() const { return model_; }

 private:
  /// One PressToForce call: the search's state and its stages (fingertip_compliance.cpp).
  class PressCall;
  /// Contact pairs of the last step touching the patch edge, or skin outside the patch at
  /// rest positions: the candidate set is then too small for this contact.
  bool TouchesOutsidePatch(const std::vector<geometry::RigidObject>& objects_model) const;
  /// True if any of `nodes` lies inside an object at its rest position (poses at t = 0).
  bool AnyInside(const std::vector<geometry::RigidObject>& objects_model, const std::vector<int>& nodes) const;
  /// Least distance [mm] from the objects to the contact points and the skin outside the
  /// patch, all at rest: with no contact force the skin is at rest, and objects moved by
  /// less touch none of them. 0 unless every shape's distance is a true distance (Lipschitz).
  double ClearanceAtRest_mm(const std::vector<geometry::RigidObject>& objects_model) const;
  std::vector<geometry::RigidObject> ToModel(const std::vector<geometry::RigidObject>& objects_pad) const;
  /// A tangential load along pad x, y [N] in the model frame.
  Eigen::Vector3d TangentialToModel(const Eigen::Vector2d& tangential_pad_N) const;

  const model::FingertipModel& model_;
  FingertipComplianceOptions options_;
  std::unique_ptr<fem::ComplianceContact> contact_;
  Eigen::Matrix3Xd merkel_rest_pad_mm_;
  std::vector<char> on_edge_;           // per candidate
  std::vector<char> sample_on_edge_;    // per contact sample (a face's: any vertex on the edge)
  std::vector<int> candidate_index_;    // per soft node: index into candidates, or -1
  std::vector<int> outside_skin_;       // skin nodes that are not candidates
  double last_indentation_mm_ = -1, last_target_N_ = 0;
  // Local exponent m of F ~ d^m at the last answer (Hertz's 1.5 until one is measured).
  double last_exponent_ = 1.5;
  bool exponent_measured_ = false;
  // Indentation of the contact state left by the last PressToForce solve; -1 = unknown
  // (a Step() with other objects, or never pressed).
  double state_indentation_mm_ = -1;
};

}  // namespace sedbridge::scene
