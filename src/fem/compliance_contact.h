#pragma once
// Contact at haptic rates by the compliance method (the idea of SOFA's
// PrecomputedConstraintCorrection): the contact solver. Its operator (W = H K^-1 H^T over
// the candidate nodes, G = S K^-1 H^T to the SED's nodes, precomputed and cached:
// fem/compliance_operator.h) and its SED mapping (fem/compliance_sed_map.h) are their own
// classes; this one holds the step. A step solves the paper's penalty law f_i = k max(0, -phi(x_i)) n(x_i) (SDF and normal at
// the CURRENT node position x = X + u, as PenaltyContactForce in a quasi-static solve) on
// this small system: with the gaps linearized at the current positions it is a convex QP
// in the contacts' normal force magnitudes (primal active set); outer iterations move the
// linearization (normals of curved objects), Anderson-accelerated, and everything is
// warm-started from the last step. Then the Merkel SED from G f. Same equilibrium as the
// full FE quasi-static Newton solve with PenaltyContactForce on the same candidate nodes
// (to relative_tolerance). Optional: exact (non-penetrating) contact, k -> infinity.
// Not thread-safe (one instance per thread).
//
// Units: SI throughout (m, N, Pa).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fem/compliance_operator.h"
#include "fem/compliance_sed_map.h"
#include "fem/dense_cholesky.h"
#include "fem/force_term.h"
#include "fem/penalty_contact_force.h"
#include "fem/tet_mesh.h"
#include "common/geometry/rigid_object.h"

namespace sedbridge::fem {

struct ComplianceContactOptions {
  double stiffness_N_m = 1e4;      ///< k_contact per node (paper: 1e4 N/m)
  /// Exact (rigid, non-penetrating) contact instead of the penalty law: gaps >= 0, forces
  /// >= 0, a force only where the gap is closed (k -> infinity; stiffness_N_m unused).
  /// Converged when gaps are within relative_tolerance * 1 mm of that.
  bool exact_contact = false;
  /// Pseudo-friction springs (as PseudoFrictionForce with coulomb_mu = 0): a contact that
  /// existed at the last EndStep() is tied tangentially to where it touched the object,
  /// stiffness friction_anisotropy * k. 0 = frictionless. Not with exact_contact. The
  /// Coulomb cap (sliding anchors) is not supported: the quasi-static full FE Newton
  /// diverges on it too (tried: a plane slid over a block, mu 0.2 and 1.0).
  double friction_anisotropy = 0.0;
  /// Outer iterations per step (each a QP with the gaps linearized at the current positions,
  /// Anderson-accelerated); with monotone_fallback, as many again where they fail.
  int max_iterations = 60;
  /// A frictionless displacement-controlled penalty step that has not converged in
  /// max_iterations goes on for as many again unaccelerated: a descent on the penalty
  /// energy that cannot cycle (ComplianceContact::MonotoneFallbackApplies says why), where
  /// Anderson's extrapolation can (a pin display's press: docs/display-rendering.md).
  /// Iterations then counts both. Off by default: a step that fails either way would report
  /// a later state than before, and the bridge's every-scan press has fallbacks of its own
  /// (on for a display pressed on the leader: render::DisplayLeaderOptions).
  bool monotone_fallback = false;
  /// Also keep K^-1 H^T for every node (3 #nodes x 3 #candidates: 24 MB on model B) so
  /// that full_positions_m() gives the whole deformed mesh (VTU frames). Built by the
  /// precompute (the disk cache holds only W and G, so it is not read then).
  bool full_field = false;
  /// Converged when every contact's normal force matches k * depth at the new positions
  /// to this fraction of the largest contact force (and the active set is unchanged).
  double relative_tolerance = 1e-8;
  /// Folder for the precompute cache (created if missing); empty = no disk cache.
  std::string cache_dir;
  /// OpenMP threads for the precompute's back-substitutions; 0 = OpenMP's default.
  int precompute_threads = 0;
  /// The Merkel SED's two passes run on the caller's OpenMP team (omp_get_max_threads: a
  /// scene's chosen team, the bridge's fe threads) only from these sizes on; below, a
  /// parallel region's start and barrier cost more than the pass. Entries of G read by its
  /// product (3 x loaded nodes x SED rows; a 10-contact sphere on B reads 0.12 M) ...
  double sed_parallel_min_entries = 1.5e6;
  /// ... and elements of the linear SED pass.
  int sed_parallel_min_elements = 4000;
  /// Memory for the SED's kept columns [MiB]: a node whose force comes along the same
  /// direction as at the last SED (a plane's contacts, step after step) gets one column
  /// G(:, node) d (single precision, as G), so the SED's product reads one column for it
  /// instead of three. 0 = none (every node through its three columns).
  double sed_kept_columns_MiB = 64;
  /// Face contact: these points on skin faces take part in the contact as the candidate
  /// nodes do (the penalty law at their own positions), so that an object narrower than
  /// the node spacing is caught by the faces between nodes (docs/bridge-fidelity.md#the-measure).
  /// W is then over nodes and samples, B W B^T with B the interpolation, built after the
  /// precompute (the cache holds the nodes' blocks); the products go through the nodes.
  /// Empty: node contact, the paper's and the full FE's.
  std::vector<ContactSample> face_samples;
  /// An operator another contact built for the same mesh object, candidate nodes, SED nodes,
  /// face samples and full_field (ComplianceContact::shared_operator()): used read-only
  /// instead of a precompute of its own (a hand's fingers on one leader model). Null: built
  /// here. Throws std::invalid_argument when it does not fit.
  std::shared_ptr<const ComplianceOperator> shared_operator;
};

/// One contact step's answer. Contacts are (node, object) pairs, as PenaltyContactForce.
struct ComplianceStepResult {
  bool ok = false;          ///< false: bad input (non-finite pose/force); nothing else is valid
  bool converged = false;   ///< met relative_tolerance within its iterations (ComplianceContactOptions::max_iterations)
  /// Force control only: the warm start's forces touch nothing where the objects start
  /// (they moved since), so the step stopped at once (not converged); start it again from
  /// no contact (ResetWarmStart).
  bool stale_warm_start = false;
  int iterations = 0;
  std::string error;
  std::vector<ActiveContact> contacts;  ///< node = mesh node index, object = index into objects
  Eigen::Vector3d spring_force_N = Eigen::Vector3d::Zero();  ///< sum k depth n on the skin (model frame)
  Eigen::Vector3d tangential_force_N = Eigen::Vector3d::Zero();  ///< tangential load applied (model frame)
  Eigen::Vector3d friction_force_N = Eigen::Vector3d::Zero();    ///< sum of pseudo-friction spring forces
  Eigen::Vector3d sample_load_N = Eigen::Vector3d::Zero();       ///< sum of the held sample loads (model frame)
  Eigen::VectorXd sed_Pa;   ///< SED per vertex, in the order of sed_vertices()
};

/// What the contact QPs did since construction (where a step's time goes).
struct ComplianceQpCounts {
  std::uint64_t qps = 0;                ///< linearized QPs solved (one per outer iteration)
  std::uint64_t factorizations = 0;     ///< Cholesky factorizations of a QP matrix
  std::uint64_t factor_reuses = 0;      ///< QP solves on the last factor (matrix unchanged)
  std::uint64_t factor_updates = 0;     ///< rows appended to or removed from the factor
  std::uint64_t columns_computed = 0;   ///< columns W dir computed for T
  std::uint64_t combined_predictions = 0;  ///< Anderson moves predicted without a pass over W
  std::uint64_t sed_columns_kept = 0;   ///< SED columns G(:, node) d computed (kept for reuse)
  std::uint64_t sed_kept_reads = 0;     ///< node forces the SED took through a kept column
  /// Steps whose accelerated iterations ran out and that went on unaccelerated
  /// (ComplianceContactOptions::monotone_fallback).
  std::uint64_t monotone_fallbacks = 0;
};

class ComplianceContact {
 public:
  /// @param mesh            rest mesh (must outlive this object)
  /// @param terms           the model's own force terms: a linear ElasticTetForce plus
  ///                        constant-Jacobian supports (the fixed bone coupling); K is
  ///                        assembled from them at rest
  /// @param candidate_nodes nodes that may touch (mesh indices, unique)
  /// @param sed_vertices    nodes where the SED is wanted (the Merkel layer's vertices)
  /// @param options         contact stiffness, iteration control, cache folder
  /// Throws std::invalid_argument if the model is not linear with a constant K, or K is
  /// singular (no support).
  ComplianceContact(const TetMesh& mesh, std::vector<std::unique_ptr<ForceTerm>> terms,
                    std::vector<int> candidate_nodes, std::vector<int> sed_vertices,
                    ComplianceContactOptions options = {});
  ~ComplianceContact();

  /// Contact with rigid objects (model frame, posed at time t_s), plus an optional total
  /// tangential load [N, model frame] spread over the contacts in proportion to their
  /// normal force (ignored while nothing touches). Warm-started from the last call.
  /// With compute_sed = false the step leaves sed_Pa and positions_m() as they were (a
  /// root find that needs only the force: PressToForce); ComputeSed() fills them later.
  const ComplianceStepResult& Step(const std::vector<geometry::RigidObject>& objects, double t_s = 0.0,
                                   const Eigen::Vector3d& tangential_force_N = Eigen::Vector3d::Zero(),
                                   bool compute_sed = true);
  /// Force control: the objects move together along `direction` by an offset the step
  /// finds with the contact forces, so that the force they apply along it is target_N.
  /// The offset is the Lagrange multiplier of that force in the step's QP (a rigid
  /// indenter under a dead load), so one step answers what a root find over
  /// displacement-controlled steps answers in several.
  struct ForceControl {
    Eigen::Vector3d direction_unit = -Eigen::Vector3d::UnitZ();  ///< how the objects move (model frame)
    double target_N = 0;       ///< wanted sum of contact forces . direction_unit (> 0)
    double offset_m = 0;       ///< in: where to start; out: the answer's offset along direction
    /// Most the offset moves in one outer iteration [m]: the SDF is evaluated at displaced
    /// nodes, so a longer move lets nodes tunnel through a thin object (as
    /// scene::PressToForceOptions::max_step_mm).
    double max_change_m = 0.2e-3;
    double max_offset_m = 5e-3;  ///< beyond this (or below 0) the step gives up
  };
  /// One step under force control (see ForceControl); objects posed at t = 0 plus the
  /// offset. Frictionless penalty contact only (with exact_contact or friction springs it
  /// fails with an error). converged = false if the force or the penalty law is not met
  /// within max_iterations, or the offset leaves [0, max_offset_m]; then the caller falls
  /// back to displacement-controlled steps (the warm start is reset).
  const ComplianceStepResult& StepToForce(const std::vector<geometry::RigidObject>& objects, ForceControl& control,
                                          const Eigen::Vector3d& tangential_force_N = Eigen::Vector3d::Zero(),
                                          bool compute_sed = true);
  /// An external load held fixed on the contact points [N, model frame], one column per
  /// contact point (num_samples() columns: the candidate nodes, then the face samples), kept
  /// for every step until changed or cleared (a display's suction over its holes). A step
  /// solves the contact with it: displacements W (contact forces + tangential share + this
  /// load), the Merkel SED from all of them. Not with force control (StepToForce refuses).
  /// An all-zero load clears it. Throws std::invalid_argument for the wrong size or a
  /// non-finite entry.
  void SetSampleLoads(const Eigen::Matrix3Xd& force_N);
  void ClearSampleLoads();
  bool has_sample_loads() const { return !load_samples_.empty(); }
  /// The held load (num_samples() columns; empty when none is held) [N, model frame].
  const Eigen::Matrix3Xd& sample_loads_N() const { return sample_load_N_; }

  /// The last step's Merkel SED (result sed_Pa) and positions_m(), from its contact forces;
  /// what Step does at its end unless told not to. No-op if the last step failed.
  void ComputeSed();
  /// True when sed_Pa and positions_m() belong to the last step.
  bool sed_current() const { return sed_current_; }
  const ComplianceStepResult& last() const { return result_; }
  const ComplianceQpCounts& qp_counts() const { return qp_counts_; }
  /// Forgets the warm start (the next step starts from no contact) and friction anchors.
  void ResetWarmStart();
  /// The warm start (contact forces and directions of the last step), to try a step and
  /// go back if it is not taken (PressToForce's force-controlled try).
  struct WarmStart {
    int num_objects = -1;
    Eigen::VectorXd lambda_N;
    Eigen::Matrix3Xd normal;
  };
  WarmStart SaveWarmStart() const { return {num_objects_, lambda_N_, normal_}; }
  /// True if the warm start carries a contact force (else the next step starts from the
  /// skin at rest).
  bool HasContactForces() const { return (lambda_N_.array() > 0).any(); }
  /// Back to a saved warm start (friction anchors are not part of it: unchanged).
  void RestoreWarmStart(const WarmStart& w);
  /// Accepts the last step for pseudo friction (as a simulation's EndStep): contacts
  /// anchor where they touch now, sliding anchors move. No-op without friction.
  void EndStep();
  size_t num_anchors() const;

  /// Contact points: the candidate nodes, then options.face_samples.
  int num_samples() const { return op_->num_samples(); }
  /// The contact points' rest positions [m], 3 x num_samples().
  const Eigen::Matrix3Xd& sample_rest_positions_m() const { return op_->sample_rest_positions_m(); }
  /// Displacement of each candidate after the last step [m], 3 x #candidates.
  Eigen::Map<const Eigen::Matrix3Xd> candidate_displacements_m() const;
  /// Positions of all nodes where the last step defines them (candidates and SED nodes;
  /// every other node stays at rest) [m], 3 * #nodes.
  const Eigen::VectorXd& positions_m() const { return x_; }
  /// Every node's position after the last step [m], 3 * #nodes (options.full_field only;
  /// empty otherwise).
  Eigen::VectorXd full_positions_m() const { return op_->FullPositions(loaded_, f_c_); }

  const std::vector<int>& candidate_nodes() const { return op_->candidate_nodes(); }
  const std::vector<int>& sed_vertices() const { return sed_map_->vertices(); }
  /// Nodes whose displacement the SED needs (those of the elements around sed_vertices).
  const std::vector<int>& sed_nodes() const { return sed_map_->sed_nodes(); }
  /// W [m/N] over the num_samples() contact points and G [m/N] over the candidate nodes
  /// (see the file comment; a face sample's force reaches G through its nodes).
  const Eigen::MatrixXd& compliance_m_N() const { return op_->W(); }
  const Eigen::MatrixXd& sed_node_map_m_N() const { return op_->G(); }
  /// The Merkel SED's mapping (its last displacements, element strains, vertex average).
  const ComplianceSedMap& sed_map() const { return *sed_map_; }
  /// The precomputed operator (W, G, the cache) this contact solves with.
  const ComplianceOperator& compliance_operator() const { return *op_; }
  /// The same operator, for another contact on this mesh to share (shared_operator).
  std::shared_ptr<const ComplianceOperator> shared_operator() const { return op_; }

  const ComplianceContactOptions& options() const { return options_; }
  /// The solve's tolerance (ComplianceContactOptions::relative_tolerance) for the steps
  /// that follow; the precompute does not depend on it. Throws std::invalid_argument
  /// unless 0 < tolerance < 1.
  void set_relative_tolerance(double tolerance);
  /// Wall time of the precompute (or cache load) [s] and where it came from.
  double precompute_s() const { return precompute_s_; }
  bool loaded_from_cache() const { return op_->loaded_from_cache(); }
  /// Cache file used (empty without cache_dir).
  const std::string& cache_file() const { return op_->cache_file(); }
  /// Why an existing cache file was not used (empty if none was rejected).
  const std::string& cache_rejected_reason() const { return op_->cache_rejected_reason(); }

 private:
  // Exact contact's gap tolerance is relative_tolerance times this length [m].
  static constexpr double kExactGapScale_m = 1e-3;
  // Exact contact: compliance added to the QP matrix, relative to its largest diagonal
  // entry [-]. Far below any physical compliance (the answer does not move), large enough to
  // keep the matrix definite when two contacts push one node along dependent normals.
  static constexpr double kExactContactRegularization = 1e-12;
  // Floor of the largest contact force used to scale the penalty gap tolerance [N]: before
  // any force is known the tolerance must still be positive.
  static constexpr double kMinForceScale_N = 1e-12;
  // A point whose gap is known to exceed this [m] is not evaluated again within a step (it
  // can only come into contact by moving that far; the QP sees the bound as its gap).
  static constexpr double kFarGap_m = 0.5e-3;
  // Force control: a row whose direction turns less than this [-] toward the push cannot
  // start carrying the force (its force would be huge, its gap closing from far away).
  static constexpr double kMinPush = 1e-3;

  // One Solve's state besides the members: force control's offset along its direction and
  // its Anderson history, and this iteration's measures of the penalty law.
  struct SolveState {
    ForceControl* control = nullptr;
    double offset = 0;
    double previous_mapped_offset = 0;  // the offset's mapped value at the last iteration
    bool offset_capped = false;         // the last move was cut to max_change_m
    bool have_previous = false;         // Anderson history valid (same contacts as last iteration)
    bool previous_prediction_valid = false;  // previous_prediction_ = W (last QP's mapped forces)
    bool warm_forces = false;           // force control from forces of the last step
    double warm_gap_m = 0;              // least gap of a warm force, at the start
    double largest = 0, mismatch = 0, gap_error = 0, turn = 0;
    double pushed_N = 0;                // force control: sum k depth n . direction
  };
  const ComplianceStepResult& Solve(const std::vector<geometry::RigidObject>& objects, double t_s,
                                    const Eigen::Vector3d& tangential_force_N, bool compute_sed, ForceControl* control);
  // Solve's stages, in order.
  /// Clears the result, checks the inputs, sizes the pairs for these objects and poses them.
  bool BeginSolve(const std::vector<geometry::RigidObject>& objects, double t_s,
                  const Eigen::Vector3d& tangential_force_N, SolveState& state);
  /// Poses the objects at their base pose plus force control's offset.
  void PlaceObjects(const SolveState& state);
  /// 1. The forces of the current pairs on the samples (normal, tangential share, friction)
  /// and the displacements they give; returns the tangential load per unit normal force.
  Eigen::Vector3d LoadCurrentForces(const Eigen::Vector3d& tangential_force_N);
  /// 2. Gaps and normals at the current positions, and how far the forces are from the
  /// law. False on a non-finite signed distance (result_.error set).
  bool EvaluateGaps(const std::vector<geometry::RigidObject>& objects, int iteration, SolveState& state);
  /// Whether a step that ran out of accelerated iterations goes on unaccelerated
  /// (options_.monotone_fallback and a step it holds for; the comment in the .cpp says why
  /// that converges).
  bool MonotoneFallbackApplies(const ForceControl* control, const Eigen::Vector3d& tangential_force_N) const;
  /// The convergence test of the penalty law (or exact contact, or force control).
  bool LawIsMet(const SolveState& state) const;
  /// Anderson acceleration of depth 1 on the pairs' force vectors after a QP; returns its
  /// coefficient (0: none).
  double AccelerateForces(const Eigen::Vector3d& tangential_force_N, SolveState& state);
  /// Force control: moves the objects by the QP's offset change (capped, accelerated).
  /// False when the offset left its bounds (the solve stops).
  bool MoveObjects(double accelerated_gamma, SolveState& state);
  /// The contacts and forces the final positions give (as PenaltyContactForce).
  void ReportContacts(const Eigen::Vector3d& tangential_force_N);
  /// u_c = W f_c over the candidates whose force is non-zero. normal_forces_only: f_c is
  /// exactly the pairs' l_p n_p (no friction, no tangential load), so cached columns of T
  /// can serve.
  void CandidateDisplacements(bool normal_forces_only);
  /// The slot of T's column for QP row r (W dir_r at its sample), or -1 when the row has
  /// none: a column is kept for a row's current sample and direction, and computed the
  /// second time the row comes with them.
  int RowColumn(int r);
  /// The slot of row r's column if it holds W dir at `sample`, else -1.
  int CachedRowColumn(int r, int sample, const Eigen::Vector3d& dir) const;
  /// y += sum over `items` of coefficient_of(item) T(:, slot_of(item)).
  template <typename Items, typename SlotOf, typename CoefficientOf>
  void AddColumnsOfT(const Items& items, const SlotOf& slot_of, const CoefficientOf& coefficient_of,
                     Eigen::VectorXd& y) const;
  /// One convex QP for the normal forces with the gaps linearized at the current
  /// positions (see compliance_contact_qp.cpp); updates lambda_N_. False on NaN.
  /// With `control`: the force along its direction is its target, and qp_offset_change_m_
  /// is how far the objects move for it (the multiplier of that constraint).
  bool SolveLinearizedQp(int num_objects, const Eigen::Vector3d& tau, const ForceControl* control = nullptr);
  // SolveLinearizedQp's stages.
  /// The QP's rows (normal rows of every pair, then friction rows) and the held tangential
  /// load's displacements u_t_; returns the number of rows.
  int BuildQpRows(int num_objects, const Eigen::Vector3d& tau);
  /// Force control: the rows' push along its direction and a start that carries the target.
  /// False when no row can carry it.
  bool StartForceControl(int rows, const ForceControl& control);
  /// u_new_ = u_t + sum over the passive rows of l_r W dir_r (from T where a row has its column).
  void PredictDisplacements(const Eigen::VectorXd& l);
  /// The primal active-set iterations; returns whether the active set settled. False in
  /// *ok on NaN or a singular matrix.
  bool RunActiveSet(int rows, const ForceControl* control, double* delta, bool* ok);
  /// The QP's row forces back to the pairs (normal forces, friction springs).
  void TakeQpForces();
  /// QP matrix entry of rows r and q (their slots of T, -1: none), compliance not included.
  double QpEntry(int r, int slot_r, int q, int slot_q) const;
  /// Brings factor_ to the passive rows (passive_, passive_slot_; `rows` QP rows): kept as
  /// is, updated by the rows that joined or left, or factored anew; passive_ and
  /// passive_slot_ then follow the factor's row order. False if the matrix is not positive
  /// definite.
  bool UpdateFactor(int rows);
  /// The Merkel SED's forces (the loaded samples' forces, through the nodes with face
  /// samples) into the SED map.
  void AddSedForces();

  const TetMesh& mesh_;
  std::vector<std::unique_ptr<ForceTerm>> terms_;
  ComplianceContactOptions options_;
  std::unique_ptr<ComplianceSedMap> sed_map_;
  std::shared_ptr<const ComplianceOperator> op_;
  NodeForceScratch op_scratch_;  // this contact's own: op_ may be shared
  double precompute_s_ = 0;

  // Per-step state: contact pairs p = candidate * #objects + object.
  int num_objects_ = -1;
  Eigen::VectorXd lambda_N_;          // normal force magnitude per pair (warm start)
  Eigen::Matrix3Xd normal_;           // unit normal per pair (direction of its force)
  Eigen::VectorXd phi_m_;             // signed distance per pair at the current positions
  // ... where and what it was at the pair's last evaluation in this step (skipping far points)
  Eigen::VectorXd phi_evaluated_, offset_evaluated_;
  Eigen::Matrix3Xd x_evaluated_;
  std::vector<char> skippable_;       // per object: a 1-Lipschitz SDF
  Eigen::VectorXd f_c_, u_c_, u_t_;   // candidate forces, displacements, tangential part
  std::vector<int> active_, loaded_;  // pairs penetrating now; candidates with a force
  Eigen::MatrixXd J_;  // the QP's matrix when it is factored anew (lower triangle)
  Eigen::VectorXd rhs_, z_, y_, u_new_, push_passive_;
  Eigen::VectorXd prediction_, previous_prediction_;  // QPs' W mapped (Anderson's combination)
  // T: W dir_r for QP rows r, one column per slot (3 x #samples rows), kept while the row's
  // sample and direction stay the same: the QP's matrix is gathered from it (J(a, b) =
  // dir_a . T(sample_a, b)) and its predictions are sums of its columns, so a row unchanged
  // since the last QP reads W not at all and its prediction a third of it.
  Eigen::MatrixXd T_;
  std::vector<int> t_slot_of_row_, t_sample_;
  std::vector<Eigen::Vector3d> t_dir_;
  std::vector<char> t_has_column_;
  std::vector<int> from_w_, from_t_, passive_slot_, with_column_, without_column_;
  ComplianceQpCounts qp_counts_;
  // The QP matrix's Cholesky factor and, per factor row, the QP row and what its entries
  // were computed from (updated by rows while that holds).
  struct FactorRow {
    int sample;
    Eigen::Vector3d dir;
    double compliance;
  };
  UpdatableCholesky factor_;
  std::vector<int> factor_rows_, row_slot_;
  std::vector<FactorRow> factor_keys_;
  std::vector<char> factor_keep_;
  std::vector<double> factor_column_;
  bool prediction_valid_ = false;  // u_new_ = W f of the current forces (QP's last prediction)
  // Pseudo friction, per pair: anchor in the object's frame, current spring force, the
  // force the law asks at the current positions, and whether a spring acts (anchored and
  // in contact).
  std::vector<char> anchored_, sticking_;
  Eigen::Matrix3Xd anchor_, anchor_world_, friction_, friction_target_;
  // QP rows: the normal row of every pair, then two tangential rows per sticking pair.
  std::vector<int> row_node_;
  Eigen::Matrix3Xd row_dir_;
  Eigen::VectorXd row_gap_, row_lambda_, row_compliance_;
  int bounded_rows_ = 0;
  Eigen::VectorXd held_;  // forces held fixed during a QP (the tangential load, the sample loads)
  // The held sample loads (SetSampleLoads; empty: none) and the points that carry one.
  Eigen::Matrix3Xd sample_load_N_;
  std::vector<int> load_samples_;
  // Anderson(1) on the force vectors l_p n_p, over the pairs that carry force (sorted pair
  // indices and their vectors: most of the pad's points carry none, and dense 3 x #pairs
  // sweeps were a tenth of a rod's press).
  struct PairVectors {
    std::vector<int> pairs;
    std::vector<Eigen::Vector3d> values;
    void clear() { pairs.clear(), values.clear(); }
    void push(int p, const Eigen::Vector3d& v) { pairs.push_back(p), values.push_back(v); }
  };
  PairVectors state_, mapped_, residual_, previous_mapped_, previous_residual_;
  std::vector<int> passive_, before_add_, kept_;
  std::vector<char> in_passive_;
  double largest_ = 0;
  std::vector<Eigen::Isometry3d> pose_, pose_inverse_, base_pose_;  // per object, this step
  Eigen::VectorXd row_push_;        // force control: dir . row direction per QP row
  double qp_offset_change_m_ = 0;   // force control: the QP's move of the objects
  std::vector<Eigen::Matrix3d> pose_rotation_;
  Eigen::VectorXd x_;
  bool sed_current_ = false;
  ComplianceStepResult result_;
};

}  // namespace sedbridge::fem
