#include "scene/fingertip_compliance.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <stdexcept>

#include "fem/elastic_tet_force.h"
#include "fem/mesh_topology.h"

namespace sedbridge::scene {

namespace {

// Bracket width of the force-controlled press below which it has collapsed [mm]: far below
// any change of depth that changes the force, so the target force cannot be matched.
constexpr double kCollapsedBracket_mm = 1e-12;
// The press brackets the target force by power-law steps (F ~ d^m) aimed this factor past
// it [-] while it knows no local exponent: close enough that the root find starts from a
// tight bracket (scan after scan the force changes by about 1 %), far enough that the step
// brackets it.
constexpr double kBracketOvershoot = 1.02;
// Smallest bracketing step [mm]: below any indentation change a scan asks for.
constexpr double kMinBracketStep_mm = 1e-4;
// Bounds on a measured force-indentation exponent m of F ~ d^m (a penalty-contact flat is
// near 1, a sphere growing its patch over a curved pad steeper than Hertz's 1.5).
constexpr double kMinExponent = 0.8, kMaxExponent = 4.0;
// A cold force-controlled press starts where the objects first reach the skin at rest,
// found by sphere tracing (each step the least clearance): stopped when the clearance is
// below this [mm] (the force-controlled step closes the rest: it moves up to max_step_mm an
// outer iteration) or after this many steps.
constexpr double kApproachClearance_mm = 0.02;
constexpr int kMaxApproachSteps = 16;

// Indentation at which a contact with F ~ d^m through (d_mm, force_N) reaches target_N [mm].
double PowerLawDepth_mm(double d_mm, double force_N, double target_N, double exponent) {
  return d_mm * std::pow(target_N / force_N, 1.0 / exponent);
}

// The exponent of the power law through two (indentation, force) points; `fallback` if
// they do not define one (a force or depth <= 0, the same depth, a falling force).
double LocalExponent(double d0_mm, double f0_N, double d1_mm, double f1_N, double fallback) {
  if (!(d0_mm > 0 && d1_mm > 0 && f0_N > 0 && f1_N > 0)) return fallback;
  const double dl = std::log(d1_mm / d0_mm);
  if (!(std::abs(dl) > 1e-9)) return fallback;
  const double m = std::log(f1_N / f0_N) / dl;
  return std::isfinite(m) && m > 0 ? std::clamp(m, kMinExponent, kMaxExponent) : fallback;
}

}  // namespace

FingertipComplianceOptions ComplianceOptionsFromScene(const SceneDescription& d) {
  auto refuse = [](const std::string& why) {
    throw std::invalid_argument("the compliance contact solver needs a linear quasi-static scene with the bone fixed: " +
                                why);
  };
  if (d.elasticity != fem::ElasticFormulation::kLinear) refuse("the scene is corotational");
  if (d.integrator.kind != fem::IntegratorKind::kQuasiStatic) refuse("the scene is dynamic (backward Euler)");
  if (!d.bone) refuse("the scene has no bone section (K would be singular)");
  if (d.bone->motion) refuse("the bone is tracked");
  if (d.friction && d.friction->coulomb_mu > 0)
    refuse("friction.coulomb_mu > 0 (only sticking pseudo-friction springs are supported)");
  if (d.surface_traction) refuse("the scene has surface traction");
  if (d.outputs.full_sed) refuse("outputs.full_sed needs every node's displacement (the method has the pad's and the Merkel layer's)");
  FingertipComplianceOptions o;
  o.bone = d.bone->spring;
  if (d.contact) o.contact.stiffness_N_m = d.contact->params.stiffness_N_m;
  o.contact.cache_dir = d.solver_cache_dir;
  if (d.friction) o.contact.friction_anisotropy = d.friction->anisotropy;
  return o;
}

const char* ToString(PressStatus s) {
  switch (s) {
    case PressStatus::kReached: return "reached";
    case PressStatus::kMaxDepth: return "max_depth";
    case PressStatus::kPatchEdge: return "patch_edge";
    case PressStatus::kNoContact: return "no_contact";
    case PressStatus::kAboveTarget: return "above_target";
    case PressStatus::kInvalidInput: return "invalid_input";
    case PressStatus::kNotConverged: return "not_converged";
  }
  return "?";
}

FingertipCompliance::FingertipCompliance(const model::FingertipModel& m, FingertipComplianceOptions options)
    : model_(m), options_(std::move(options)) {
  const Eigen::Matrix3Xd& rest = m.soft.rest_positions_m;
  const Eigen::Vector3d z_pad = m.pad_frame.model_from_pad.linear().col(2);

  // Candidates: skin facing the pad, not deeper than max_depth_mm below the origin.
  const auto normals = fem::VertexNormals(m.skin_triangles, rest, m.skin_nodes);
  std::vector<int> candidates;
  candidate_index_.assign(size_t(m.num_soft_nodes()), -1);
  for (size_t k = 0; k < m.skin_nodes.size(); ++k) {
    const int n = m.skin_nodes[k];
    const double depth_mm = -m.pad_frame.ToPad(rest.col(n)).z() * 1e3;
    if (normals[k].dot(z_pad) >= options_.min_facing && depth_mm <= options_.max_depth_mm) {
      candidate_index_[size_t(n)] = int(candidates.size());
      candidates.push_back(n);
    } else {
      outside_skin_.push_back(n);
    }
  }
  if (candidates.empty()) throw std::invalid_argument("compliance contact: no skin node faces the pad");
  on_edge_.assign(candidates.size(), 0);
  for (const auto& t : m.skin_triangles)
    for (int a = 0; a < 3; ++a) {
      const int i = candidate_index_[size_t(t[size_t(a)])];
      if (i < 0) continue;
      for (int b = 0; b < 3; ++b)
        if (candidate_index_[size_t(t[size_t(b)])] < 0) on_edge_[size_t(i)] = 1;
    }

  sample_on_edge_ = on_edge_;
  if (options_.face_samples) {
    std::vector<fem::ContactSample>& samples = options_.contact.face_samples;
    samples.clear();
    for (const auto& t : m.skin_triangles) {
      fem::ContactSample sample;
      char edge = 0;
      for (int a = 0; a < 3; ++a) {
        sample.candidate[size_t(a)] = candidate_index_[size_t(t[size_t(a)])];
        sample.weight[size_t(a)] = 1.0 / 3.0;
        if (sample.candidate[size_t(a)] >= 0) edge = char(edge | on_edge_[size_t(sample.candidate[size_t(a)])]);
      }
      if (*std::min_element(sample.candidate.begin(), sample.candidate.end()) < 0) continue;
      samples.push_back(sample);
      sample_on_edge_.push_back(edge);
    }
    options_.contact.stiffness_N_m *= double(candidates.size()) / double(candidates.size() + samples.size());
  }

  // The model's own support, as FingertipScene builds it.
  std::vector<std::unique_ptr<fem::ForceTerm>> terms;
  terms.push_back(std::make_unique<fem::ElasticTetForce>(m.soft, fem::ElasticFormulation::kLinear));
  std::vector<Eigen::Vector3d> bone_normals;
  if (options_.bone.anisotropy != 1.0) {
    const std::set<int> attached(m.attached_nodes.begin(), m.attached_nodes.end());
    std::vector<fem::Triangle> interface;
    for (const auto& f : fem::BoundaryFaces(m.soft.tets, rest))
      if (attached.count(f[0]) && attached.count(f[1]) && attached.count(f[2])) interface.push_back(f);
    bone_normals = fem::VertexNormals(interface, rest, m.attached_nodes);
  }
  terms.push_back(std::make_unique<fem::BoneCouplingForce>(rest, m.attached_nodes, bone_normals, options_.bone));
  contact_ = std::make_unique<fem::ComplianceContact>(m.soft, std::move(terms), std::move(candidates), m.merkel_nodes,
                                                      options_.contact);

  merkel_rest_pad_mm_.resize(3, Eigen::Index(m.merkel_nodes.size()));
  for (size_t k = 0; k < m.merkel_nodes.size(); ++k)
    merkel_rest_pad_mm_.col(Eigen::Index(k)) = m.pad_frame.ToPad(rest.col(m.merkel_nodes[k])) * 1e3;
}

std::vector<geometry::RigidObject> FingertipCompliance::ToModel(const std::vector<geometry::RigidObject>& objects) const {
  std::vector<geometry::RigidObject> out;
  out.reserve(objects.size());
  for (const auto& o : objects) out.push_back({o.name, o.shape, o.trajectory.Transformed(model_.pad_frame.model_from_pad)});
  return out;
}

const fem::ComplianceStepResult& FingertipCompliance::Step(const std::vector<geometry::RigidObject>& objects_pad,
                                                           double t_s, const Eigen::Vector2d& tangential_pad_N) {
  const Eigen::Vector3d t_model = TangentialToModel(tangential_pad_N);
  state_indentation_mm_ = -1;
  return contact_->Step(ToModel(objects_pad), t_s, t_model);
}

void FingertipCompliance::ResetWarmStart() {
  contact_->ResetWarmStart();
  state_indentation_mm_ = 0;
}

Eigen::Vector3d FingertipCompliance::TangentialToModel(const Eigen::Vector2d& tangential_pad_N) const {
  return model_.pad_frame.model_from_pad.linear() * Eigen::Vector3d(tangential_pad_N.x(), tangential_pad_N.y(), 0.0);
}

void FingertipCompliance::SetSampleLoads(const Eigen::Matrix3Xd& force_pad_N) {
  contact_->SetSampleLoads(model_.pad_frame.model_from_pad.linear() * force_pad_N);
}

double FingertipCompliance::normal_force_N() const {
  const Eigen::Vector3d z_pad = model_.pad_frame.model_from_pad.linear().col(2);
  return -z_pad.dot(contact_->last().spring_force_N);
}

bool FingertipCompliance::AnyInside(const std::vector<geometry::RigidObject>& objects_model,
                                    const std::vector<int>& nodes) const {
  for (const auto& o : objects_model) {
    const Eigen::Isometry3d object_from_model = o.trajectory.Pose(0.0).inverse();  // once, not per node
    for (int n : nodes)
      if (o.shape->Evaluate(object_from_model * model_.soft.rest_positions_m.col(n)).distance_m < 0) return true;
  }
  return false;
}

double FingertipCompliance::ClearanceAtRest_mm(const std::vector<geometry::RigidObject>& objects_model) const {
  double least_m = std::numeric_limits<double>::infinity();
  const Eigen::Matrix3Xd& samples = contact_->sample_rest_positions_m();
  for (const auto& o : objects_model) {
    if (!o.shape || !o.shape->lipschitz()) return 0.0;
    const Eigen::Isometry3d object_from_model = o.trajectory.Pose(0.0).inverse();
    for (Eigen::Index k = 0; k < samples.cols(); ++k)
      least_m = std::min(least_m, o.shape->Evaluate(object_from_model * samples.col(k)).distance_m);
    for (int n : outside_skin_)
      least_m = std::min(least_m, o.shape->Evaluate(object_from_model * model_.soft.rest_positions_m.col(n)).distance_m);
  }
  return std::isfinite(least_m) ? std::max(0.0, least_m) * 1e3 : 0.0;
}

bool FingertipCompliance::TouchesOutsidePatch(const std::vector<geometry::RigidObject>& objects_model) const {
  for (const auto& c : contact_->last().contacts)
    if (sample_on_edge_[size_t(c.sample)]) return true;
  // Skin outside the patch moves little where the contact is: inside an object at rest
  // means it would be in contact in the full model.
  return AnyInside(objects_model, outside_skin_);
}

// One PressToForce call: its objects, target and options, the evaluations so far (the last
// two aim the next) and the result being built. Its methods are the stages of the search, in
// the order Run takes them: the press at indentation 0, the starting depth, one
// force-controlled solve, the first evaluation there, the bracket, and the root find.
class FingertipCompliance::PressCall {
 public:
  PressCall(FingertipCompliance& fingertip, const std::vector<geometry::RigidObject>& objects_pad, double target_N,
            const PressToForceOptions& opt, const Eigen::Vector2d& tangential_pad_N)
      : fc_(fingertip), contact_(*fingertip.contact_), objects_pad_(objects_pad), target_N_(target_N), opt_(opt),
        tangential_pad_N_(tangential_pad_N), tol_(opt.relative_tolerance * target_N) {
    r_.target_force_N = target_N;
  }

  PressToForceResult Run() {
    if (!PosesAtTouch()) return r_;
    // Friction anchors belong to a stepped scene, not to a hypothesis being pressed.
    if (fc_.options_.contact.friction_anisotropy > 0) contact_.ResetWarmStart();
    t_model_ = fc_.TangentialToModel(tangential_pad_N_);
    if (auto done = AtZero()) return *done;
    StartDepth();
    if (auto done = ForceControlled()) return *done;
    if (auto done = FromStartDepth()) return *done;
    if (auto done = Bracket()) return *done;
    return RootFind();
  }

 private:
  static constexpr const char* kEdge = "contact reaches the edge of the candidate patch (object near the pad's edge)";

  bool PosesAtTouch() {
    for (const auto& o : objects_pad_) {
      touch_.push_back(o.trajectory.Pose(0.0));
      if (!touch_.back().matrix().allFinite()) {
        r_.message = "non-finite object pose";
        return false;
      }
    }
    return true;
  }

  // The objects at indentation d [mm] (translated by -d along z_pad) in the model frame.
  std::vector<geometry::RigidObject> AtDepth(double d_mm) const {
    std::vector<geometry::RigidObject> moved = objects_pad_;
    for (size_t k = 0; k < moved.size(); ++k)
      moved[k].trajectory = geometry::Trajectory(Eigen::Translation3d(0, 0, -d_mm * 1e-3) * touch_[k]);
    return fc_.ToModel(moved);
  }
  // The same, as the contact state's.
  void Place(double d_mm) {
    last_model_ = AtDepth(d_mm);
    fc_.state_indentation_mm_ = d_mm;
  }
  // Normal force at indentation d [mm].
  double ForceAt(double d_mm) {
    Place(d_mm);
    // The root find needs only the force: the SED once, at the answer (Finish).
    const fem::ComplianceStepResult& s = contact_.Step(last_model_, 0.0, t_model_, /*compute_sed=*/false);
    ++r_.iterations;
    if (!s.ok) solve_failed_ = true;
    if (!s.converged) solve_unconverged_ = true;
    return s.ok ? fc_.normal_force_N() : 0.0;
  }
  double Evaluate(double d_mm) {
    const double f = ForceAt(d_mm);
    r_.indentation_mm = d_mm;
    d_prev_ = d_last_, f_prev_ = f_last_, d_last_ = d_mm, f_last_ = f;
    return f;
  }
  // Exponent and aim of the next step: measured from this call's last two evaluations, else
  // the last answer's; aimed at the target itself once an exponent is measured (a good aim
  // lands within the tolerance, saving the solve a bracket would cost), else past it.
  double Exponent() const { return LocalExponent(d_prev_, f_prev_, d_last_, f_last_, fc_.last_exponent_); }
  double Aim() const {
    return LocalExponent(d_prev_, f_prev_, d_last_, f_last_, 0.0) > 0 || fc_.exponent_measured_
               ? 1.0 + 0.25 * opt_.relative_tolerance
               : kBracketOvershoot;
  }

  PressToForceResult Finish(PressStatus status, double d_mm, double f_N, const std::string& why) {
    // The contact state must be the answer's: re-solve where the answer is if the last
    // evaluation was elsewhere.
    if (r_.indentation_mm != d_mm || r_.iterations == 0) f_N = ForceAt(d_mm);
    contact_.ComputeSed();
    r_.indentation_mm = d_mm;
    r_.force_N = f_N;
    r_.status = status;
    std::set<int> nodes;
    for (const auto& c : contact_.last().contacts) nodes.insert(c.node);
    r_.active_nodes = int(nodes.size());
    if (status == PressStatus::kReached && fc_.TouchesOutsidePatch(last_model_)) {
      r_.status = PressStatus::kPatchEdge;
      r_.message = kEdge;
    } else if (status == PressStatus::kReached && solve_unconverged_) {
      r_.status = PressStatus::kNotConverged;
      r_.message = "a contact solve did not converge";
    } else {
      r_.message = why;
    }
    r_.reached = r_.status == PressStatus::kReached;
    if (r_.reached) {
      fc_.last_indentation_mm_ = d_mm, fc_.last_target_N_ = target_N_;
      const double m = LocalExponent(d_prev_, f_prev_, d_last_, f_last_, 0.0);
      if (m > 0) fc_.last_exponent_ = m, fc_.exponent_measured_ = true;
    }
    return r_;
  }

  // At indentation 0 the force is zero unless a candidate is inside an object at rest
  // (no force, no displacement): then no solve is needed there.
  std::optional<PressToForceResult> AtZero() {
    if (!fc_.AnyInside(AtDepth(0.0), contact_.candidate_nodes())) return std::nullopt;
    f_lo_ = Evaluate(0.0);
    if (solve_failed_) return Finish(PressStatus::kInvalidInput, 0.0, 0.0, contact_.last().error);
    if (std::abs(f_lo_ - target_N_) <= tol_) return Finish(PressStatus::kReached, 0.0, f_lo_, "");
    if (f_lo_ > target_N_)
      return Finish(PressStatus::kAboveTarget, 0.0, f_lo_, "objects press harder than the target at indentation 0");
    return std::nullopt;
  }

  // Bracket by marching from the contact state's own indentation (the last answer, when
  // the objects are pressed scan after scan) in steps of at most max_step_mm (see there).
  // A state left by other objects can put this one's skin nodes on the far side of it
  // (tunnelled): its force then fails to grow with the indentation. Then start again from
  // no contact at indentation 0, once.
  void StartDepth() {
    const double state = fc_.state_indentation_mm_;
    f_zero_ = f_lo_;
    if (state < 0) contact_.ResetWarmStart();
    d_ = std::clamp(state > 0 ? state : 0.0, 0.0, opt_.max_indentation_mm);
    // The state is the last answer (scan after scan): start where its power law puts the new
    // target, at most max_step_mm away (thin objects: see there).
    if (state > 0 && state == fc_.last_indentation_mm_ && fc_.last_target_N_ > 0)
      d_ = std::clamp(PowerLawDepth_mm(state, fc_.last_target_N_, target_N_, fc_.last_exponent_),
                      std::max(0.0, state - opt_.max_step_mm), std::min(opt_.max_indentation_mm, state + opt_.max_step_mm));
  }

  // From no contact state (a touch's first scan) the force-controlled step would walk the
  // objects to the skin max_step_mm an outer iteration (18 of them, 1.1 ms, for the rig's
  // sphere at the pad's corner, whose lowest point is 2.9 mm above the skin there), and its
  // last move onto the skin could land a thin rod in another equilibrium than a continuous
  // push (ColdPressOfAThinRodFindsTheSlowMarchsEquilibrium). With no force the skin is at
  // rest, and moving the objects by the clearance at rest touches nothing: start where those
  // moves meet the skin.
  double ApproachAtRest() const {
    double start_mm = 0;
    for (int k = 0; k < kMaxApproachSteps && start_mm < opt_.max_indentation_mm; ++k) {
      const double clearance_mm = fc_.ClearanceAtRest_mm(AtDepth(start_mm));
      start_mm = std::min(opt_.max_indentation_mm, start_mm + clearance_mm);
      if (!(clearance_mm > kApproachClearance_mm)) break;
    }
    return start_mm;
  }
  // One force-controlled contact solve of the objects (poses at touch, model frame) from
  // indentation from_mm; *d_mm: where it left them.
  const fem::ComplianceStepResult& ForceControlledSolve(const std::vector<geometry::RigidObject>& at_touch,
                                                        double from_mm, double* d_mm) {
    fem::ComplianceContact::ForceControl control;
    control.direction_unit = -fc_.model_.pad_frame.model_from_pad.linear().col(2);
    control.target_N = target_N_;
    control.offset_m = from_mm * 1e-3;
    control.max_change_m = std::max(1e-3, opt_.max_step_mm) * 1e-3;
    control.max_offset_m = opt_.max_indentation_mm * 1e-3;
    const fem::ComplianceStepResult& s = contact_.StepToForce(at_touch, control, t_model_, /*compute_sed=*/false);
    ++r_.iterations;
    *d_mm = control.offset_m * 1e3;
    return s;
  }
  // One force-controlled solve from the starting depth: the indentation comes with the
  // contact forces. Only from a state without force at indentation 0 (f_zero = 0), and
  // frictionless.
  std::optional<PressToForceResult> ForceControlled() {
    if (!(opt_.force_control && f_zero_ == 0 && !(fc_.options_.contact.friction_anisotropy > 0) &&
          !fc_.options_.contact.exact_contact))
      return std::nullopt;
    const double start_mm = d_ == 0 && !contact_.HasContactForces() ? ApproachAtRest() : d_;
    const std::vector<geometry::RigidObject> at_touch = fc_.ToModel(objects_pad_);  // poses at t = 0
    const fem::ComplianceContact::WarmStart before = contact_.SaveWarmStart();
    double d_mm = 0;  // where the force-controlled step left the objects
    const fem::ComplianceStepResult* s = &ForceControlledSolve(at_touch, start_mm, &d_mm);
    // The last answer's contacts do not touch these objects where they start (the estimate
    // moved: the rig's pad-corner sphere, whose warm contacts were on the finger's side,
    // then walked 24 moves to the 5 mm bound, 6.5 ms): press them from no contact instead.
    if (s->stale_warm_start) {
      contact_.ResetWarmStart();
      s = &ForceControlledSolve(at_touch, ApproachAtRest(), &d_mm);
    }
    const double f_N = s->ok ? fc_.normal_force_N() : 0.0;
    if (s->ok && s->converged && !s->contacts.empty() && std::abs(f_N - target_N_) <= tol_) {
      Place(d_mm);
      r_.indentation_mm = d_mm;
      r_.force_controlled = true;
      return Finish(PressStatus::kReached, d_mm, f_N, "");
    }
    // Not answered (not converged, out of depth, patch edge or no contact): the root find
    // below, from the state force control started from.
    contact_.RestoreWarmStart(before);
    return std::nullopt;
  }

  void Restart() {
    contact_.ResetWarmStart();
    restarted_ = true;
    d_ = 0;
    f_ = f_zero_;
  }
  // The force at the starting depth (from a state that tunnelled: from no contact).
  std::optional<PressToForceResult> FromStartDepth() {
    f_ = f_zero_;
    restarted_ = d_ <= 0;
    if (d_ > 0) {
      f_ = Evaluate(d_);
      if (solve_failed_) return Finish(PressStatus::kInvalidInput, d_, f_, contact_.last().error);
      if (std::abs(f_ - target_N_) <= tol_) return Finish(PressStatus::kReached, d_, f_, "");
      if (f_ <= 0 || contact_.last().contacts.empty()) Restart();
    }
    return std::nullopt;
  }

  // [lo, hi] around the target, by power-law steps up from below it or back from above it.
  std::optional<PressToForceResult> Bracket() {
    hi_ = d_, f_hi_ = f_;
    std::optional<PressToForceResult> done = f_ < target_N_ ? BracketUp() : BracketDown();
    if (done) return done;
    if (std::abs(f_hi_ - target_N_) <= tol_) return Finish(PressStatus::kReached, hi_, f_hi_, "");
    return std::nullopt;
  }
  std::optional<PressToForceResult> BracketUp() {
    const double step_max = std::max(1e-3, opt_.max_step_mm);
    lo_ = d_, f_lo_ = f_;
    for (;;) {
      // Below the target and already touching skin outside the patch: pushing deeper only
      // leaves the patch further (e.g. an object beside the finger).
      if (lo_ > 0 && fc_.TouchesOutsidePatch(last_model_)) return Finish(PressStatus::kPatchEdge, lo_, f_lo_, kEdge);
      if (lo_ >= opt_.max_indentation_mm) {
        if (contact_.last().contacts.empty())
          return Finish(PressStatus::kNoContact, lo_, f_lo_, "nothing touches the patch up to max_indentation_mm");
        return Finish(PressStatus::kMaxDepth, lo_, f_lo_, "target not reached at max_indentation_mm");
      }
      if (r_.iterations >= opt_.max_iterations)
        return Finish(PressStatus::kNotConverged, lo_, f_lo_, "bracketing ran out of iterations");
      // The power-law estimate (F ~ d^m) at or a little past the target, capped at max_step_mm.
      double step = step_max;
      if (f_lo_ > 0 && lo_ > 0) {
        step = std::clamp(PowerLawDepth_mm(lo_, f_lo_, Aim() * target_N_, Exponent()) - lo_, kMinBracketStep_mm, step_max);
      } else if (f_lo_ == 0 && (r_.iterations == 0 || contact_.last().contacts.empty())) {
        // Nothing pressed yet, so the skin is at rest: nothing can touch before the objects
        // have moved by the clearance, and the solves on the way would only confirm it (the
        // rig's pad-corner sphere marched 25 of them to the finger's side, ~0.5 ms).
        step = std::max(step, fc_.ClearanceAtRest_mm(AtDepth(lo_)));
      }
      hi_ = std::min(opt_.max_indentation_mm, lo_ + step);
      f_hi_ = Evaluate(hi_);
      if (solve_failed_) return Finish(PressStatus::kInvalidInput, hi_, f_hi_, contact_.last().error);
      if (std::abs(f_hi_ - target_N_) <= tol_) return Finish(PressStatus::kReached, hi_, f_hi_, "");
      if (f_hi_ < f_lo_ && !restarted_) {  // deeper and weaker: tunnelled (see StartDepth)
        Restart();
        lo_ = 0, f_lo_ = f_zero_;
        continue;
      }
      if (f_hi_ >= target_N_) return std::nullopt;
      lo_ = hi_, f_lo_ = f_hi_;
    }
  }
  std::optional<PressToForceResult> BracketDown() {
    const double step_max = std::max(1e-3, opt_.max_step_mm);
    for (;;) {
      if (hi_ <= 0)
        return Finish(PressStatus::kAboveTarget, 0.0, f_hi_, "objects press harder than the target at indentation 0");
      if (r_.iterations >= opt_.max_iterations)
        return Finish(PressStatus::kNotConverged, hi_, f_hi_, "bracketing ran out of iterations");
      // The power-law estimate at or a little short of the target, at most max_step_mm back.
      const double step =
          std::clamp(hi_ - PowerLawDepth_mm(hi_, f_hi_, target_N_ / Aim(), Exponent()), kMinBracketStep_mm, step_max);
      lo_ = std::max(0.0, hi_ - step);
      f_lo_ = Evaluate(lo_);
      if (solve_failed_) return Finish(PressStatus::kInvalidInput, lo_, f_lo_, contact_.last().error);
      if (std::abs(f_lo_ - target_N_) <= tol_) return Finish(PressStatus::kReached, lo_, f_lo_, "");
      if (f_lo_ <= target_N_) break;
      hi_ = lo_, f_hi_ = f_lo_;
    }
    if (std::abs(f_lo_ - target_N_) <= tol_) return Finish(PressStatus::kReached, lo_, f_lo_, "");
    return std::nullopt;
  }

  // Illinois (regula falsi that halves the stale end's weight): secant speed on a
  // monotone force curve with kinks where contacts join, never leaves the bracket.
  PressToForceResult RootFind() {
    int stale = 0;
    while (r_.iterations < opt_.max_iterations) {
      double d = hi_ - (f_hi_ - target_N_) * (hi_ - lo_) / (f_hi_ - f_lo_);
      if (!(d > lo_ && d < hi_)) d = 0.5 * (lo_ + hi_);
      const double f = Evaluate(d);
      if (solve_failed_) return Finish(PressStatus::kInvalidInput, d, f, contact_.last().error);
      if (std::abs(f - target_N_) <= tol_) return Finish(PressStatus::kReached, d, f, "");
      if (hi_ - lo_ < kCollapsedBracket_mm)
        return Finish(PressStatus::kNotConverged, d, f, "bracket collapsed before the force matched");
      if (f < target_N_) {
        lo_ = d, f_lo_ = f;
        if (stale == -1) f_hi_ = target_N_ + 0.5 * (f_hi_ - target_N_);
        stale = -1;
      } else {
        hi_ = d, f_hi_ = f;
        if (stale == 1) f_lo_ = target_N_ + 0.5 * (f_lo_ - target_N_);
        stale = 1;
      }
    }
    return Finish(PressStatus::kNotConverged, r_.indentation_mm, contact_.last().ok ? fc_.normal_force_N() : 0.0,
                  "root find ran out of iterations");
  }

  FingertipCompliance& fc_;
  fem::ComplianceContact& contact_;
  const std::vector<geometry::RigidObject>& objects_pad_;
  const double target_N_;
  const PressToForceOptions& opt_;
  const Eigen::Vector2d tangential_pad_N_;
  const double tol_;
  PressToForceResult r_;
  std::vector<Eigen::Isometry3d> touch_;          // the objects' poses at touch (t = 0)
  std::vector<geometry::RigidObject> last_model_;  // the objects where the contact state has them
  Eigen::Vector3d t_model_ = Eigen::Vector3d::Zero();
  bool solve_failed_ = false, solve_unconverged_ = false;
  // The last two evaluations (depth, force) of this call: their power law aims the next.
  double d_prev_ = -1, f_prev_ = 0, d_last_ = -1, f_last_ = 0;
  double f_zero_ = 0;       // force at indentation 0
  double d_ = 0, f_ = 0;    // the starting depth and its force
  bool restarted_ = false;  // from no contact at indentation 0 (once)
  double lo_ = 0, f_lo_ = 0, hi_ = 0, f_hi_ = 0;  // the bracket
};

PressToForceResult FingertipCompliance::PressToForce(const std::vector<geometry::RigidObject>& objects_pad,
                                                     double target_N, const PressToForceOptions& opt,
                                                     const Eigen::Vector2d& tangential_pad_N) {
  PressToForceResult r;
  r.target_force_N = target_N;
  if (!(std::isfinite(target_N) && target_N > 0) || objects_pad.empty() || !tangential_pad_N.allFinite() ||
      !(opt.max_indentation_mm > 0) || !(opt.relative_tolerance > 0)) {
    r.message = "target force must be finite and > 0, with at least one object";
    return r;
  }
  if (contact_->has_sample_loads()) {
    r.message = "no press to a force while sample loads are held (ClearSampleLoads first)";
    return r;
  }
  if (!(opt.contact_relative_tolerance >= 0 && opt.contact_relative_tolerance < 1)) {
    r.message = "contact_relative_tolerance must be in [0, 1) (0: the contact's own)";
    return r;
  }
  // The call's contact tolerance, the configured one back on every return.
  struct ToleranceScope {
    fem::ComplianceContact& contact;
    double configured;
    ~ToleranceScope() { contact.set_relative_tolerance(configured); }
  } tolerance_scope{*contact_, contact_->options().relative_tolerance};
  if (opt.contact_relative_tolerance > 0) contact_->set_relative_tolerance(opt.contact_relative_tolerance);
  return PressCall(*this, objects_pad, target_N, opt, tangential_pad_N).Run();
}

}  // namespace sedbridge::scene
