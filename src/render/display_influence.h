#pragma once
// What a display's commands do to the leader's Merkel layer, linear about the preloaded
// state: the layer's element strains are eps_e(u) = eps0_e + E_e u for a command vector u
// (eps0: the preload's strain; E_e: each actuator's strain per unit command), so the SED of
// any command vector is a quadratic form per element, the tet SED of fem/tet_sed.h,
// averaged to the layer's vertices
// as the bridge's SED is (S = A W). Built once per display and leader model; then the SED of
// a command vector costs one product with the 6 #elements x #actuators strain matrix (its
// Jacobian one more), microseconds. (Per-vertex #actuators^2 forms would cost #vertices x
// #actuators^2 instead: 16 times more at 64 actuators, measured slower already at 16.)

#include <Eigen/Core>
#include <memory>
#include <vector>

namespace sedbridge::render {

/// Strain components in this order: xx, yy, zz, xy, xz, yz (tensor components, not
/// engineering shear) [-].
constexpr int kStrainComponents = 6;

/// The per-element description the quadratic forms are built from.
///
/// Each actuator's strain is its own function of its command, summed over actuators (no
/// actuator-actuator interaction): zero up to command_offset[i] (a pin's gap to the skin of
/// the preloaded pad: a pin below it touches nothing), then piecewise linear in
/// v = u - offset through the knots, the last segment extended. With no knots and no
/// offsets it is the linear eps0 + E u.
struct ElementStrainInfluence {
  /// 6 #elements x #actuators: element e's strain per unit command of each actuator on the
  /// first segment, v in [0, knot_command[0]) [1/command unit], rows 6e..6e+5.
  Eigen::MatrixXd strain_per_command;
  /// Per actuator: the command below which it does nothing [command unit]; empty = all 0.
  std::vector<double> command_offset;
  /// v where the segments after the first begin, increasing, > 0 [command unit]; empty:
  /// one linear segment.
  std::vector<double> knot_command;
  /// The strain change at each knot [-] (6 #elements x #actuators each, one per knot):
  /// the response at v = knot_command[k] of each actuator alone. The segment after the last
  /// knot keeps the slope of the one before it.
  std::vector<Eigen::MatrixXd> strain_at_knot;
  /// 6 #elements: the strain of the preloaded state with every command 0 [-].
  Eigen::VectorXd preload_strain;
  Eigen::VectorXd mu_Pa, lambda_Pa;  ///< per element
  /// Vertex average: vertex v's SED is the sum over k in [start[v], start[v+1]) of
  /// weight[k] * element SED of element[k].
  std::vector<int> vertex_start, vertex_element;
  std::vector<double> vertex_weight;
};

/// Throws std::invalid_argument for inconsistent sizes, vertex ranges out of order, a vertex
/// naming no element, non-finite entries, or knots not finite, positive and increasing.
void CheckElementStrainInfluence(const ElementStrainInfluence& in);

/// The vertex SED as a function of the commands.
///
/// Only the elements some actuator strains are evaluated: an element whose strain change
/// stays below prune_relative of the largest (over actuators, knots and elements) keeps the
/// preload's SED, folded into a constant per vertex. On model B most of the Merkel layer
/// (its sides, the nail's side) is out of every display's reach; evaluating it cost more
/// memory traffic than the rest of a render.
class DisplayInfluence {
 public:
  DisplayInfluence() = default;
  /// @param prune_relative elements whose largest strain change is below this fraction of
  ///        the largest are held at the preload's strain (0: evaluate every element)
  /// Throws std::invalid_argument for inconsistent sizes or non-finite entries.
  explicit DisplayInfluence(const ElementStrainInfluence& elements, double prune_relative = 1e-4);
  /// Whether an influence of `elements` is evaluated from per-vertex quadratic forms (exact,
  /// few actuators, linear) rather than element by element.
  static bool EvaluatedByVertexForms(const ElementStrainInfluence& elements);

  int num_actuators() const { return num_actuators_; }
  int num_vertices() const { return int(fixed_sed_Pa_.size()); }
  /// Elements evaluated per call (those some actuator strains), of all of the layer's.
  int num_active_elements() const { return int(mu_Pa_.size()); }
  int num_elements() const { return num_elements_; }
  /// Vertex SED [Pa] of command vector u (#actuators), into sed_Pa (#vertices).
  void Sed(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa) const;
  /// The same and its Jacobian dS/du [Pa / command unit] (#vertices x #actuators).
  void SedAndJacobian(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa, Eigen::MatrixXd& jacobian) const;

  /// The vertices whose SED the commands can change (some active element in their average),
  /// increasing; every other vertex keeps its preload SED whatever the commands.
  const std::vector<int>& active_vertices() const { return active_vertex_; }
  /// SED of the active vertices only [Pa] (#active vertices, in active_vertices() order).
  void ActiveSed(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa) const;
  /// The same and the transposed Jacobian dS/du [Pa / command unit] (#actuators x #active
  /// vertices: one contiguous column per vertex, what a Gauss-Newton matrix is built from).
  void ActiveSedAndJacobianT(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa, Eigen::MatrixXd& jacobian_t) const;

  /// Vertex SED of the preloaded state with every command 0 [Pa].
  const Eigen::VectorXd& preload_sed_Pa() const { return preload_sed_Pa_; }
  /// The command below which actuator i does nothing [command unit].
  double command_offset(int i) const { return offset_[i]; }
  const Eigen::VectorXd& command_offsets() const { return offset_; }

 private:
  /// Keeps the elements some actuator strains; the rest go into fixed_sed_.
  struct Tables;
  void Prune(const ElementStrainInfluence& in, double prune_relative, Tables& tables);
  /// Each actuator's place on its curve at u: its segment and stroke, the slope its
  /// derivative takes; brings effective_ and intercept_ up to date with them.
  void Segments(const Eigen::VectorXd& u) const;
  /// A linear influence (no offsets, no knots) of at most this many actuators is evaluated
  /// from per-vertex quadratic forms (#actuators^2 floats a vertex: fewer bytes than the
  /// elements' 6 x #actuators each, 469 vertices against 5228 elements on B).
  static constexpr int kMaxVertexFormActuators = 32;
  /// tables.vertex_forms and vertex_constant_ from the active elements (linear influence).
  void BuildVertexForms(Tables& tables);
  /// Active vertices' SED (and transposed Jacobian) from the vertex forms.
  void FormSeds(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa, Eigen::MatrixXd* jacobian_t) const;
  /// Element SEDs element_sed_ at u and, with `gradient`, dW_e/du into element_gradient_t_
  /// (#actuators x #active elements), in one pass over the effective slopes.
  void ElementSeds(const Eigen::VectorXd& u, bool gradient) const;
  /// Segment of v >= 0: the number of knots at or below v.
  int SegmentOf(double v) const;
  /// Active vertices' SED from the element SEDs (fixed part included).
  void AverageToActiveVertices(Eigen::VectorXd& vertex) const;

  int num_actuators_ = 0, num_elements_ = 0;
  // Active elements only (rows 6e..6e+5 of each matrix).
  Eigen::VectorXd preload_strain_, mu_Pa_, lambda_Pa_;
  std::vector<double> knot_command_;
  std::vector<Eigen::MatrixXd> strain_at_knot_;
  // Segment k's slope (k = 0: from v = 0); past the last knot the last one goes on. Only
  // while the influence is built (then freed with strain_at_knot_).
  std::vector<Eigen::MatrixXd> slope_;
  // The large tables every call reads, never written once built: shared by the copies of
  // an influence (a hand's fingers each render with a copy of the renderer: one copy of the
  // tables in memory and in the cache instead of one a finger).
  struct Tables {
    // Segment k >= 1's intercept at k - 1: eps(knot k-1) - knot_{k-1} slope_k (6 #active
    // elements x #actuators each), what an actuator on that segment adds to intercept_.
    std::vector<Eigen::MatrixXf> knot_intercept;
    // slope_ in single precision, per actuator in the kernel's chunk layout: actuator i's
    // block of chunk b at (i #chunks + b) 48.
    std::vector<std::vector<float>> chunked_slope;
    // Linear influences of few actuators: per active vertex g (#actuators) and Q
    // (#actuators^2, column by column) of S = constant + g . u + u^T Q u
    // (element_sed_kernel.h), single precision, eight vertices a chunk (VertexFormIndex);
    // the constant in vertex_constant_.
    std::vector<float> vertex_forms;
  };
  std::shared_ptr<const Tables> tables_;
  // The curve each actuator is on at the last u: the slope of element e's strain component
  // c per unit stroke of actuator i at ChunkedSlopeIndex(e, c, i, n) (render/
  // element_sed_kernel.h: eight elements a chunk, one vector lane each), so that eps_e =
  // intercept_e + slopes_e . v and its gradient vectorize across elements.
  // Rebuilt only for the actuators whose segment changed (rare between evaluations). In
  // single precision: a render streams it once per evaluation, and half the bytes is
  // close to half the time; a slope's 1e-7 rounding is far below what the fit resolves
  // (the preload and knot strains, summed into intercept_, stay double).
  mutable std::vector<float> effective_;
  mutable Eigen::VectorXd intercept_, stroke_;
  mutable Eigen::VectorXf stroke_f_;
  mutable std::vector<float> scratch_;
  // The vertex forms' constants (the preload's SED, pruned elements included), in double.
  Eigen::VectorXd vertex_constant_;
  mutable std::vector<int> slope_index_, segment_, intercept_segment_;
  mutable int intercept_updates_ = 0;
  // Vertex average over the active elements for the active vertices, plus each vertex's SED
  // from the pruned ones.
  std::vector<int> active_vertex_, vertex_start_, vertex_element_;
  std::vector<double> vertex_weight_;
  Eigen::VectorXd fixed_sed_Pa_;
  Eigen::VectorXd preload_sed_Pa_, offset_;
  bool piecewise_ = false;  // any offset or knot
  mutable Eigen::VectorXd element_sed_, active_sed_;
  mutable Eigen::MatrixXf element_gradient_t_;  // single: averaged, then widened once per vertex
  mutable Eigen::MatrixXd active_jacobian_t_;
};

}  // namespace sedbridge::render
