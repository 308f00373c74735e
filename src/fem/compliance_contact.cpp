#include "fem/compliance_contact.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "fem/elastic_tet_force.h"

namespace sedbridge::fem {

namespace {

// Calls f(p, a, b) for every pair index in either sorted list, with a pointer to its vector
// in each (null where the list lacks it), in increasing order.
template <typename Lists, typename F>
void MergePairs(const Lists& a, const Lists& b, F&& f) {
  size_t i = 0, k = 0;
  while (i < a.pairs.size() || k < b.pairs.size()) {
    const int pa = i < a.pairs.size() ? a.pairs[i] : std::numeric_limits<int>::max();
    const int pb = k < b.pairs.size() ? b.pairs[k] : std::numeric_limits<int>::max();
    if (pa == pb) {
      f(pa, &a.values[i++], &b.values[k++]);
    } else if (pa < pb) {
      f(pa, &a.values[i++], nullptr);
    } else {
      f(pb, nullptr, &b.values[k++]);
    }
  }
}

ComplianceOperatorOptions OperatorOptionsOf(const ComplianceContactOptions& o) {
  ComplianceOperatorOptions op;
  op.full_field = o.full_field;
  op.cache_dir = o.cache_dir;
  op.precompute_threads = o.precompute_threads;
  op.face_samples = o.face_samples;
  return op;
}

ComplianceSedMapOptions SedMapOptionsOf(const ComplianceContactOptions& o) {
  ComplianceSedMapOptions s;
  s.kept_columns_MiB = o.sed_kept_columns_MiB;
  s.parallel_min_entries = o.sed_parallel_min_entries;
  s.parallel_min_elements = o.sed_parallel_min_elements;
  return s;
}

}  // namespace

ComplianceContact::ComplianceContact(const TetMesh& mesh, std::vector<std::unique_ptr<ForceTerm>> terms,
                                     std::vector<int> candidate_nodes, std::vector<int> sed_vertices,
                                     ComplianceContactOptions options)
    : mesh_(mesh), terms_(std::move(terms)), options_(std::move(options)) {
  const auto t0 = std::chrono::steady_clock::now();
  const ElasticTetForce& elastic = LinearElasticTermOf(terms_);
  if (options_.exact_contact && options_.friction_anisotropy > 0)
    throw std::invalid_argument("compliance contact: pseudo friction needs the penalty law (not exact_contact)");
  sed_map_ = std::make_unique<ComplianceSedMap>(elastic, std::move(sed_vertices), SedMapOptionsOf(options_));
  if (options_.shared_operator) {
    // Built once for this model by another contact (a hand's fingers on one leader model):
    // read-only here, the node scratch is this contact's own.
    op_ = std::move(options_.shared_operator);
    if (&op_->mesh() != &mesh || op_->candidate_nodes() != candidate_nodes || op_->sed_nodes() != sed_map_->sed_nodes() ||
        op_->face_samples().size() != options_.face_samples.size() || op_->has_full_field() != options_.full_field)
      throw std::invalid_argument("compliance contact: the shared operator was built for another mesh, candidates, "
                                  "SED nodes, face samples or full field");
  } else {
    SystemMatrix K;
    AssembleRestStiffness(mesh, terms_, K);
    op_ = std::make_shared<const ComplianceOperator>(mesh, K, std::move(candidate_nodes), sed_map_->sed_nodes(),
                                                     OperatorOptionsOf(options_));
  }
  op_scratch_ = op_->MakeScratch();
  sed_map_->BindOperator(op_->G());
  x_ = Eigen::Map<const Eigen::VectorXd>(mesh.rest_positions_m.data(), mesh.rest_positions_m.size());
  f_c_ = u_c_ = u_t_ = Eigen::VectorXd::Zero(3 * num_samples());
  ResetWarmStart();
  precompute_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

ComplianceContact::~ComplianceContact() = default;

Eigen::Map<const Eigen::Matrix3Xd> ComplianceContact::candidate_displacements_m() const {
  return {u_c_.data(), 3, Eigen::Index(op_->num_candidates())};
}

void ComplianceContact::set_relative_tolerance(double tolerance) {
  if (!(tolerance > 0 && tolerance < 1))
    throw std::invalid_argument("compliance contact: relative_tolerance must be in (0, 1)");
  options_.relative_tolerance = tolerance;
}

size_t ComplianceContact::num_anchors() const {
  return size_t(std::count(anchored_.begin(), anchored_.end(), char(1)));
}

void ComplianceContact::EndStep() {
  if (!(options_.friction_anisotropy > 0) || !result_.ok || num_objects_ <= 0) return;
  const int no = num_objects_;
  const Eigen::Matrix3Xd& rest = op_->sample_rest_positions_m();
  std::vector<char> next(anchored_.size(), 0);
  for (const int p : active_) {
    const Eigen::Vector3d x = rest.col(p / no) + u_c_.segment<3>(3 * (p / no));
    // Touched in this step: anchor where it is; anchored contacts keep their anchor.
    if (!anchored_[size_t(p)]) anchor_.col(p) = pose_inverse_[size_t(p % no)] * x;
    next[size_t(p)] = 1;
  }
  anchored_.swap(next);
}

void ComplianceContact::ResetWarmStart() {
  num_objects_ = -1;
  lambda_N_.resize(0);
  f_c_.setZero();
  u_c_.setZero();
}

void ComplianceContact::SetSampleLoads(const Eigen::Matrix3Xd& force_N) {
  if (force_N.cols() != num_samples() || !force_N.allFinite())
    throw std::invalid_argument("compliance contact: sample loads need one finite column per contact point (" +
                                std::to_string(num_samples()) + ")");
  load_samples_.clear();
  for (int j = 0; j < num_samples(); ++j)
    if (!force_N.col(j).isZero(0.0)) load_samples_.push_back(j);
  if (load_samples_.empty())
    sample_load_N_.resize(3, 0);
  else
    sample_load_N_ = force_N;
}

void ComplianceContact::ClearSampleLoads() {
  load_samples_.clear();
  sample_load_N_.resize(3, 0);
}

void ComplianceContact::RestoreWarmStart(const WarmStart& w) {
  if (w.num_objects < 0 || w.lambda_N.size() != w.normal.cols() || w.lambda_N.size() % std::max(1, w.num_objects) != 0 ||
      w.lambda_N.size() != Eigen::Index(num_samples()) * w.num_objects) {
    ResetWarmStart();
    return;
  }
  const bool same_scene = w.num_objects == num_objects_;
  num_objects_ = w.num_objects;
  lambda_N_ = w.lambda_N;
  normal_ = w.normal;
  if (!same_scene) {  // the per-pair friction state must have the saved scene's size
    const Eigen::Index pairs = lambda_N_.size();
    anchored_.assign(size_t(pairs), 0);
    sticking_.assign(size_t(pairs), 0);
    anchor_ = anchor_world_ = friction_ = friction_target_ = Eigen::Matrix3Xd::Zero(3, pairs);
  }
}

const ComplianceStepResult& ComplianceContact::Step(const std::vector<geometry::RigidObject>& objects, double t_s,
                                                    const Eigen::Vector3d& tangential_force_N, bool compute_sed) {
  return Solve(objects, t_s, tangential_force_N, compute_sed, nullptr);
}

const ComplianceStepResult& ComplianceContact::StepToForce(const std::vector<geometry::RigidObject>& objects,
                                                           ForceControl& control,
                                                           const Eigen::Vector3d& tangential_force_N, bool compute_sed) {
  const char* refused = nullptr;
  if (options_.exact_contact || options_.friction_anisotropy > 0)
    refused = "force control needs frictionless penalty contact";
  else if (has_sample_loads())
    refused = "force control with held sample loads is not supported";
  else if (!(control.target_N > 0 && std::isfinite(control.target_N)) || !control.direction_unit.allFinite() ||
           !(std::abs(control.direction_unit.norm() - 1.0) < 1e-9) || !(control.max_change_m > 0) ||
           !(control.max_offset_m > 0) || !std::isfinite(control.offset_m))
    refused = "force control needs a unit direction, a target > 0 and positive step bounds";
  if (refused) {
    sed_current_ = false;
    result_ = ComplianceStepResult{};
    result_.error = refused;
    return result_;
  }
  return Solve(objects, 0.0, tangential_force_N, compute_sed, &control);
}

const ComplianceStepResult& ComplianceContact::Solve(const std::vector<geometry::RigidObject>& objects, double t_s,
                                                     const Eigen::Vector3d& tangential_force_N, bool compute_sed,
                                                     ForceControl* control) {
  SolveState state;
  state.control = control;
  if (!BeginSolve(objects, t_s, tangential_force_N, state)) return result_;
  const int no = int(objects.size());
  // The accelerated iterations get max_iterations; where they fail, a step the fallback holds
  // for goes on unaccelerated for as many again (MonotoneFallbackApplies). A step that
  // converges in the accelerated iterations never reaches it.
  const bool fallback = MonotoneFallbackApplies(control, tangential_force_N);
  bool monotone = false;
  int limit = options_.max_iterations;
  for (int it = 0; it <= limit; ++it) {
    const Eigen::Vector3d tau = LoadCurrentForces(tangential_force_N);
    if (!EvaluateGaps(objects, it, state)) {
      ResetWarmStart();
      return result_;
    }
    result_.iterations = it;
    if (it == 0 && state.warm_forces && active_.empty() && state.warm_gap_m > control->max_change_m) {
      // Force control from forces that touch nothing where the objects start, every one
      // further than a move may go (the estimate moved since: the rig's pad-corner sphere,
      // whose warm contacts were on the finger's side, then walked 24 moves to the 5 mm
      // bound, 6.5 ms). Not a release (the skin just clear of the objects): the caller
      // starts from no contact.
      result_.stale_warm_start = true;
      break;
    }
    if (LawIsMet(state)) {
      result_.converged = true;
      break;
    }
    if (it == limit) {
      if (!fallback || monotone) break;
      monotone = true;  // from these positions on, every QP's forces as they are
      limit += options_.max_iterations;
      ++qp_counts_.monotone_fallbacks;
    }
    // 3. The contact problem with the gaps linearized at the current positions.
    if (!SolveLinearizedQp(no, tau, control)) {
      result_.error = control ? "force-controlled contact solve failed (no contact can carry the force, or NaN)"
                              : "contact solve produced NaN";
      ResetWarmStart();
      return result_;
    }
    const double gamma = monotone ? 0.0 : AccelerateForces(tangential_force_N, state);
    if (control && !MoveObjects(gamma, state)) break;
  }
  if (control) {
    control->offset_m = state.offset;
    if (!(state.offset >= 0 && state.offset <= control->max_offset_m)) result_.converged = false;
  }
  ReportContacts(tangential_force_N);
  result_.ok = true;
  if (compute_sed) ComputeSed();
  return result_;
}

bool ComplianceContact::MonotoneFallbackApplies(const ForceControl* control, const Eigen::Vector3d& tangential_force_N) const {
  // Why the unaccelerated iteration cannot cycle: each outer iteration replaces every pair's
  // SDF by its tangent plane at the current positions and the QP minimizes the potential
  // energy with those planes exactly, Pi_lin(u) = 1/2 u^T K u - (held loads) . u +
  // sum_p k/2 max(0, -plane_p(x_p))^2. For a convex object (a plane, a sphere, a capsule, a
  // cylinder: every display's object) phi >= its tangent plane, and k/2 max(0, -t)^2 falls
  // with t, so Pi_lin >= Pi (the true penalty energy) with equality at the current positions
  // (a far point skipped in EvaluateGaps only lowers its plane further): a
  // majorize-minimize step, Pi(next) <= Pi_lin(next) <= Pi_lin(now) = Pi(now). The energy
  // falls at every iteration and the step is a strictly convex QP (unique answer), so the
  // positions settle at a stationary point of Pi, which is the penalty law (measured: Pi fell
  // at every iteration of the 12 unaccelerated steps of pin_8x8's peak press on B, 4-68
  // iterations each). Anderson's extrapolation keeps no such descent (there a face point on a
  // pin's rounded side entered and left the contact with period 5 for 200 iterations,
  // docs/display-rendering.md), so it is left out here. Not for
  // force control (the offset's trust-region cap), friction springs or a tangential load
  // (neither is the gradient of an energy), nor exact contact (its warm start may start
  // infeasible).
  return options_.monotone_fallback && !control && !options_.exact_contact && !(options_.friction_anisotropy > 0) &&
         tangential_force_N.isZero(0.0);
}

bool ComplianceContact::BeginSolve(const std::vector<geometry::RigidObject>& objects, double t_s,
                                   const Eigen::Vector3d& tangential_force_N, SolveState& state) {
  sed_current_ = false;
  result_.ok = result_.converged = result_.stale_warm_start = false;
  result_.iterations = 0;
  result_.error.clear();
  result_.contacts.clear();
  result_.spring_force_N.setZero();
  result_.tangential_force_N.setZero();
  result_.friction_force_N.setZero();
  result_.sample_load_N.setZero();
  if (!tangential_force_N.allFinite() || !std::isfinite(t_s)) {
    result_.error = "non-finite tangential force or time";
    return false;
  }
  const int c = num_samples();
  const int no = int(objects.size());
  if (no != num_objects_) {  // a different scene: no warm start, no anchors
    num_objects_ = no;
    const Eigen::Index pairs = Eigen::Index(c) * no;
    lambda_N_ = Eigen::VectorXd::Zero(pairs);
    normal_ = Eigen::Matrix3Xd::Zero(3, pairs);
    anchored_.assign(size_t(pairs), 0);
    sticking_.assign(size_t(pairs), 0);
    anchor_ = anchor_world_ = friction_ = friction_target_ = Eigen::Matrix3Xd::Zero(3, pairs);
  }
  phi_m_.resize(lambda_N_.size());
  phi_evaluated_.resize(lambda_N_.size());
  offset_evaluated_.resize(lambda_N_.size());
  x_evaluated_.resize(3, lambda_N_.size());
  skippable_.resize(size_t(no));
  for (int o = 0; o < no; ++o) skippable_[size_t(o)] = objects[size_t(o)].shape && objects[size_t(o)].shape->lipschitz();
  pose_.resize(size_t(no));
  pose_inverse_.resize(size_t(no));
  pose_rotation_.resize(size_t(no));
  base_pose_.resize(size_t(no));
  for (int o = 0; o < no; ++o) {
    if (!objects[size_t(o)].shape) {
      result_.error = "object without a shape";
      return false;
    }
    base_pose_[size_t(o)] = objects[size_t(o)].trajectory.Pose(t_s);
  }
  // Force control moves every object by offset along its direction.
  state.offset = state.control ? state.control->offset_m : 0.0;
  PlaceObjects(state);
  state.previous_mapped_offset = state.offset;
  state.warm_forces = state.control && HasContactForces();
  state.warm_gap_m = std::numeric_limits<double>::infinity();
  prediction_valid_ = false;
  return true;
}

void ComplianceContact::PlaceObjects(const SolveState& state) {
  for (size_t o = 0; o < pose_.size(); ++o) {
    Eigen::Isometry3d pose = base_pose_[o];
    if (state.control) pose.pretranslate(state.offset * state.control->direction_unit);
    pose_[o] = pose;
    pose_inverse_[o] = pose.inverse();
    pose_rotation_[o] = pose.linear();
  }
}

Eigen::Vector3d ComplianceContact::LoadCurrentForces(const Eigen::Vector3d& tangential_force_N) {
  const bool friction = options_.friction_anisotropy > 0;
  const int c = num_samples(), no = num_objects_;
  // The iteration's state: force vector l_p n_p of every pair that carries one.
  state_.clear();
  // Normal k*depth along each pair's normal, plus the tangential load in proportion to each
  // node's normal force.
  const double total = lambda_N_.sum();
  const Eigen::Vector3d tau = total > 0 ? Eigen::Vector3d(tangential_force_N / total) : Eigen::Vector3d::Zero();
  loaded_.clear();
  f_c_.setZero();
  size_t next_load = 0;  // load_samples_ is sorted
  for (int j = 0; j < c; ++j) {
    double node_lambda = 0;
    bool rubbing = false;
    for (int o = 0; o < no; ++o) {
      const int p = j * no + o;
      if (lambda_N_[p] > 0) {
        const Eigen::Vector3d force = lambda_N_[p] * normal_.col(p);
        f_c_.segment<3>(3 * j) += force;
        node_lambda += lambda_N_[p];
        if (!friction) state_.push(p, force);  // Anderson's state (not with friction)
      }
      if (friction && !friction_.col(p).isZero(0.0)) {
        f_c_.segment<3>(3 * j) += friction_.col(p);
        rubbing = true;
      }
    }
    const bool held = next_load < load_samples_.size() && load_samples_[next_load] == j;
    if (held) f_c_.segment<3>(3 * j) += sample_load_N_.col(j), ++next_load;
    if (node_lambda > 0 || rubbing || held) loaded_.push_back(j);
    if (node_lambda > 0) f_c_.segment<3>(3 * j) += node_lambda * tau;
  }
  // The QP's last prediction is exactly W f for these forces unless Anderson moved them or
  // the tangential share changed with them (never valid with sample loads).
  if (prediction_valid_ && tangential_force_N.isZero(0.0))
    u_c_.swap(u_new_);
  else
    CandidateDisplacements(!friction && tangential_force_N.isZero(0.0) && !has_sample_loads());
  prediction_valid_ = false;
  return tau;
}

bool ComplianceContact::EvaluateGaps(const std::vector<geometry::RigidObject>& objects, int it, SolveState& state) {
  // Exact contact (no penetration, k -> infinity): forces only where the gap is closed,
  // gaps >= 0 everywhere; the mismatch is then the gap error times a stiffness scale.
  const bool exact = options_.exact_contact, friction = options_.friction_anisotropy > 0;
  const double k = options_.stiffness_N_m, k_t = options_.friction_anisotropy * options_.stiffness_N_m;
  const ForceControl* control = state.control;
  const Eigen::Matrix3Xd& rest = op_->sample_rest_positions_m();
  const int c = num_samples(), no = int(objects.size());
  active_.clear();
  // Locals, written back at the end: through `state` every store to the pair arrays could
  // alias them, and the loop is the step's hottest.
  double largest = 0, mismatch = 0, gap_error = 0, turn = 0, pushed_N = 0;
  double warm_gap_m = state.warm_gap_m;
  const double offset = state.offset;
  const bool warm_forces = state.warm_forces;
  for (int j = 0; j < c; ++j) {
    const Eigen::Vector3d x = rest.col(j) + u_c_.segment<3>(3 * j);
    for (int o = 0; o < no; ++o) {
      const int p = j * no + o;
      // A point without force that was far from a 1-Lipschitz object at its last
      // evaluation in this step, and has not moved that far since, is still out of
      // contact: its gap is left at that lower bound (the QP then only sees it as nearer
      // than it is) and the SDF is not evaluated (most points, most iterations).
      if (it > 0 && !exact && !friction && lambda_N_[p] == 0 && skippable_[size_t(o)]) {
        // The objects moved too (force control): by at most |offset change|.
        const double bound =
            phi_evaluated_[p] - (x - x_evaluated_.col(p)).norm() - std::abs(offset - offset_evaluated_[p]);
        if (bound > kFarGap_m) {
          phi_m_[p] = bound;
          continue;
        }
      }
      // As RigidObject::Evaluate, with the pose computed once a step.
      geometry::SdfSample s = objects[size_t(o)].shape->Evaluate(pose_inverse_[size_t(o)] * x);
      s.normal = pose_rotation_[size_t(o)] * s.normal;
      if (warm_forces && it == 0 && lambda_N_[p] > 0) warm_gap_m = std::min(warm_gap_m, s.distance_m);
      phi_m_[p] = s.distance_m;
      phi_evaluated_[p] = s.distance_m;
      offset_evaluated_[p] = offset;
      x_evaluated_.col(p) = x;
      if (!std::isfinite(s.distance_m) || !s.normal.allFinite()) {
        result_.error = "non-finite signed distance (object pose?)";
        return false;
      }
      if (exact) {
        const double lp = lambda_N_[p];
        gap_error = std::max(gap_error, lp > 0 ? std::abs(s.distance_m) : std::max(0.0, -s.distance_m));
        if (lp > 0) {
          turn = std::max(turn, lp * (s.normal - normal_.col(p)).norm());
          largest = std::max(largest, lp);
          active_.push_back(p);
        }
        normal_.col(p) = s.normal;
      } else if (s.distance_m < 0) {
        const double target = -k * s.distance_m;
        mismatch = std::max(mismatch, (target * s.normal - lambda_N_[p] * normal_.col(p)).norm());
        if (control) pushed_N += target * s.normal.dot(control->direction_unit);
        largest = std::max(largest, target);
        normal_.col(p) = s.normal;
        active_.push_back(p);
        if (friction && anchored_[size_t(p)]) {
          // The spring PseudoFrictionForce applies here (no Coulomb cap).
          anchor_world_.col(p) = pose_[size_t(o)] * anchor_.col(p);
          const Eigen::Matrix3d tangential = Eigen::Matrix3d::Identity() - s.normal * s.normal.transpose();
          const Eigen::Vector3d ft = -k_t * (tangential * (x - anchor_world_.col(p)));
          sticking_[size_t(p)] = 1;
          friction_target_.col(p) = ft;
          mismatch = std::max(mismatch, (ft - friction_.col(p)).norm());
        } else if (friction) {
          sticking_[size_t(p)] = 0;
          friction_target_.col(p).setZero();
          mismatch = std::max(mismatch, friction_.col(p).norm());
        }
      } else {
        mismatch = std::max(mismatch, lambda_N_[p]);
        normal_.col(p) = s.normal;
        if (friction) {
          sticking_[size_t(p)] = 0;
          friction_target_.col(p).setZero();
          mismatch = std::max(mismatch, friction_.col(p).norm());
        }
      }
    }
  }
  state.largest = largest, state.mismatch = mismatch, state.gap_error = gap_error, state.turn = turn;
  state.pushed_N = pushed_N, state.warm_gap_m = warm_gap_m;
  return true;
}

bool ComplianceContact::LawIsMet(const SolveState& state) const {
  const double tolerance = options_.relative_tolerance;
  if (options_.exact_contact)
    return state.gap_error <= tolerance * kExactGapScale_m &&
           state.turn <= tolerance * state.largest;
  if (state.control) {
    // The penalty law as a plain step, and the force: each active pair within the law's
    // tolerance bounds the force's error by #active times it.
    const double law = tolerance * state.largest;
    return !active_.empty() && state.mismatch <= law &&
           std::abs(state.pushed_N - state.control->target_N) <= double(active_.size()) * law;
  }
  return state.mismatch <= tolerance * state.largest || (active_.empty() && state.mismatch == 0);
}

double ComplianceContact::AccelerateForces(const Eigen::Vector3d& tangential_force_N, SolveState& state) {
  // The QP freezes the normals; they turn as the skin slides over a curved object, and that
  // outer iteration converges only linearly (rate ~0.3 measured on B). Anderson
  // acceleration of depth 1 on the force vectors, while the contact set holds, makes it
  // superlinear in practice. (Not with friction springs: their forces are not along the
  // normals.)
  if (options_.friction_anisotropy > 0) return 0;
  double accelerated_gamma = 0;  // set when Anderson moved the forces
  bool combined = false;         // ... and u_new_ is W times the moved forces
  const bool qp_predicted = prediction_valid_ && tangential_force_N.isZero(0.0);  // u_new_ = W mapped
  mapped_.clear();
  for (Eigen::Index p = 0; p < lambda_N_.size(); ++p)
    if (lambda_N_[p] > 0) mapped_.push(int(p), lambda_N_[p] * normal_.col(p));
  // residual = mapped - state on the union of their pairs (both sorted).
  residual_.clear();
  MergePairs(mapped_, state_, [&](int p, const Eigen::Vector3d* m, const Eigen::Vector3d* s) {
    residual_.push(p, (m ? *m : Eigen::Vector3d::Zero()) - (s ? *s : Eigen::Vector3d::Zero()));
  });
  if (state.have_previous && mapped_.pairs == previous_mapped_.pairs) {
    double dd = 0, rd = 0;  // |r - r_previous|^2 and r . (r - r_previous)
    MergePairs(residual_, previous_residual_, [&](int, const Eigen::Vector3d* r, const Eigen::Vector3d* q) {
      const Eigen::Vector3d rv = r ? *r : Eigen::Vector3d::Zero();
      const Eigen::Vector3d dr = rv - (q ? *q : Eigen::Vector3d::Zero());
      dd += dr.squaredNorm();
      rd += rv.dot(dr);
    });
    const double gamma = dd > 0 ? rd / dd : 0.0;
    if (std::isfinite(gamma) && std::abs(gamma) < 10) {
      accelerated_gamma = gamma;
      size_t moved = 0;
      for (size_t i = 0; i < mapped_.pairs.size(); ++i) {
        const int p = mapped_.pairs[i];
        const Eigen::Vector3d accelerated = mapped_.values[i] - gamma * (mapped_.values[i] - previous_mapped_.values[i]);
        const double norm = accelerated.norm();
        // Keep the QP's contact set and directions that stay outward of the object.
        if (norm > 0 && accelerated.dot(normal_.col(p)) > 0) {
          ++moved;
          lambda_N_[p] = norm;
          normal_.col(p) = accelerated / norm;
        }
      }
      // W is linear: when every pair took the accelerated force, W times it is the same
      // combination of this QP's prediction and the last one's (no pass over W).
      combined = qp_predicted && state.previous_prediction_valid && moved == mapped_.pairs.size();
      if (combined) {
        ++qp_counts_.combined_predictions;
        prediction_.swap(u_new_);  // prediction_: this QP's W mapped
        u_new_ = prediction_ - gamma * (prediction_ - previous_prediction_);
        prediction_.swap(previous_prediction_);
      } else if (moved > 0) {
        prediction_valid_ = false;
      }
    }
  }
  if (!combined) {  // this QP's prediction W mapped is the next combination's previous one
    state.previous_prediction_valid = qp_predicted;
    if (qp_predicted) previous_prediction_ = u_new_;
  }
  std::swap(previous_mapped_, mapped_);
  std::swap(previous_residual_, residual_);
  state.have_previous = true;
  return accelerated_gamma;
}

bool ComplianceContact::MoveObjects(double accelerated_gamma, SolveState& state) {
  const ForceControl& control = *state.control;
  // The QP's move, cut to max_change_m (a trust region against tunnelling), and accelerated
  // with the forces' coefficient while neither this nor the last was cut.
  const double change = std::clamp(qp_offset_change_m_, -control.max_change_m, control.max_change_m);
  const bool capped = change != qp_offset_change_m_;
  const double mapped_offset = state.offset + change;
  state.offset = mapped_offset;
  if (accelerated_gamma != 0 && !capped && !state.offset_capped)
    state.offset = mapped_offset - accelerated_gamma * (mapped_offset - state.previous_mapped_offset);
  state.previous_mapped_offset = mapped_offset;
  state.offset_capped = capped;
  if (capped) state.have_previous = false;
  if (!(state.offset >= -control.max_change_m && state.offset <= control.max_offset_m + control.max_change_m))
    return false;
  PlaceObjects(state);
  return true;
}

void ComplianceContact::ReportContacts(const Eigen::Vector3d& tangential_force_N) {
  // What the positions say (k * depth at the final gaps), as PenaltyContactForce.
  const int no = num_objects_;
  const double k = options_.stiffness_N_m;
  const double total = lambda_N_.sum();
  const std::vector<int>& sample_node = op_->sample_nodes();
  for (int p : active_) {
    const int i = p / no;
    const double spring = options_.exact_contact ? lambda_N_[p] : -k * phi_m_[p];
    result_.contacts.push_back(
        {sample_node[size_t(i)], p % no, normal_.col(p), std::max(0.0, -phi_m_[p]), spring, spring, i});
    result_.spring_force_N += spring * normal_.col(p);
  }
  if (total > 0) result_.tangential_force_N = tangential_force_N;
  for (int j : load_samples_) result_.sample_load_N += sample_load_N_.col(j);
  result_.friction_force_N.setZero();
  if (options_.friction_anisotropy > 0)
    for (Eigen::Index p = 0; p < friction_.cols(); ++p) result_.friction_force_N += friction_.col(p);
}

void ComplianceContact::ComputeSed() {
  if (!result_.ok || sed_current_) return;
  // SED from the displacements of the nodes it reads (G f: most of a step with few
  // contacts, so a root find over many steps asks for it only at its answer).
  AddSedForces();
  const Eigen::VectorXd& u_s = sed_map_->ComputeDisplacements();
  const std::vector<int>& sed_nodes = sed_map_->sed_nodes();
  for (size_t a = 0; a < sed_nodes.size(); ++a) {
    const int v = sed_nodes[a];
    x_.segment<3>(3 * v) = mesh_.rest_positions_m.col(v) + u_s.segment<3>(3 * Eigen::Index(a));
  }
  const std::vector<int>& candidates = op_->candidate_nodes();
  const Eigen::Matrix3Xd& rest = op_->sample_rest_positions_m();
  for (size_t j = 0; j < candidates.size(); ++j)
    x_.segment<3>(3 * candidates[j]) = rest.col(Eigen::Index(j)) + u_c_.segment<3>(3 * Eigen::Index(j));
  sed_map_->ComputeSed(result_.sed_Pa);
  qp_counts_.sed_columns_kept = sed_map_->columns_kept();
  qp_counts_.sed_kept_reads = sed_map_->kept_reads();
  sed_current_ = true;
}

void ComplianceContact::AddSedForces() {
  if (op_->face_samples().empty()) {  // the candidates' own columns
    sed_map_->BeginForces(Eigen::Index(loaded_.size()));
    for (int j : loaded_) sed_map_->AddNodeForce(j, f_c_.segment<3>(3 * j));
    return;
  }
  // G is over the nodes: the samples' forces go to their nodes first.
  for (int j : loaded_) op_->AddSampleForce(j, f_c_.segment<3>(3 * j), op_scratch_);
  sed_map_->BeginForces(Eigen::Index(op_scratch_.forced_nodes.size()));
  op_->TakeNodeForces([&](int node, const Eigen::Vector3d& f) { sed_map_->AddNodeForce(node, f); }, op_scratch_);
}

}  // namespace sedbridge::fem
