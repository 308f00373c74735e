#include "render/display_influence.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fem/tet_sed.h"
#include "render/element_sed_kernel.h"

namespace sedbridge::render {

void CheckElementStrainInfluence(const ElementStrainInfluence& in) {
  const Eigen::Index elements = in.mu_Pa.size();
  const bool sizes = in.lambda_Pa.size() == elements && in.preload_strain.size() == kStrainComponents * elements &&
                     in.strain_per_command.rows() == kStrainComponents * elements && !in.vertex_start.empty() &&
                     in.vertex_start.front() == 0 && size_t(in.vertex_start.back()) == in.vertex_element.size() &&
                     in.vertex_element.size() == in.vertex_weight.size();
  if (!sizes) throw std::invalid_argument("display influence: inconsistent sizes");
  for (size_t v = 0; v + 1 < in.vertex_start.size(); ++v)
    if (in.vertex_start[v] > in.vertex_start[v + 1]) throw std::invalid_argument("display influence: vertex ranges out of order");
  for (int e : in.vertex_element)
    if (e < 0 || e >= elements) throw std::invalid_argument("display influence: a vertex names no element");
  if (!in.strain_per_command.allFinite() || !in.preload_strain.allFinite() || !in.mu_Pa.allFinite() ||
      !in.lambda_Pa.allFinite())
    throw std::invalid_argument("display influence: non-finite strain or material");
  const Eigen::Index actuators = in.strain_per_command.cols();
  if (!in.command_offset.empty() && Eigen::Index(in.command_offset.size()) != actuators)
    throw std::invalid_argument("display influence: one command offset per actuator");
  for (double g : in.command_offset)
    if (!(g >= 0) || !std::isfinite(g)) throw std::invalid_argument("display influence: command offsets finite and >= 0");
  if (in.strain_at_knot.size() != in.knot_command.size())
    throw std::invalid_argument("display influence: one strain matrix per knot");
  for (size_t k = 0; k < in.knot_command.size(); ++k) {
    if (!(in.knot_command[k] > (k ? in.knot_command[k - 1] : 0.0)) || !std::isfinite(in.knot_command[k]))
      throw std::invalid_argument("display influence: knots finite, > 0 and increasing");
    if (in.strain_at_knot[k].rows() != in.strain_per_command.rows() || in.strain_at_knot[k].cols() != actuators ||
        !in.strain_at_knot[k].allFinite())
      throw std::invalid_argument("display influence: a knot's strain matrix has the wrong size or a non-finite entry");
  }
}


bool DisplayInfluence::EvaluatedByVertexForms(const ElementStrainInfluence& in) {
  const bool offsets = std::any_of(in.command_offset.begin(), in.command_offset.end(), [](double g) { return g > 0; });
  return in.knot_command.empty() && !offsets && in.strain_per_command.cols() <= kMaxVertexFormActuators;
}

DisplayInfluence::DisplayInfluence(const ElementStrainInfluence& in, double prune_relative) {
  CheckElementStrainInfluence(in);
  num_actuators_ = int(in.strain_per_command.cols());
  num_elements_ = int(in.mu_Pa.size());
  offset_ = in.command_offset.empty()
                ? Eigen::VectorXd::Zero(num_actuators_)
                : Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(in.command_offset.data(), num_actuators_));
  piecewise_ = !in.knot_command.empty() || (offset_.array() > 0).any();
  auto tables = std::make_shared<Tables>();
  Prune(in, prune_relative, *tables);
  if (EvaluatedByVertexForms(in)) {
    BuildVertexForms(*tables);
    // The forms answer every call now: the element kernel's slopes would only hold memory.
    std::vector<std::vector<float>>().swap(tables->chunked_slope);
    std::vector<float>().swap(effective_);
  }
  tables_ = std::move(tables);
  // Every call reads the single-precision copies (chunked slopes, knot intercepts) from here
  // on: the double matrices they came from would only hold memory (170 MB on a 64-pin
  // display with five knots on B).
  std::vector<Eigen::MatrixXd>().swap(slope_);
  std::vector<Eigen::MatrixXd>().swap(strain_at_knot_);
  Sed(Eigen::VectorXd::Zero(num_actuators_), preload_sed_Pa_);
}

void DisplayInfluence::Prune(const ElementStrainInfluence& in, double prune_relative, Tables& tables) {
  // Each element's largest strain change over actuators and knots (or per command unit on
  // a linear influence).
  const std::vector<Eigen::MatrixXd> linear{in.strain_per_command};
  const std::vector<Eigen::MatrixXd>& changes = in.knot_command.empty() ? linear : in.strain_at_knot;
  Eigen::VectorXd reach = Eigen::VectorXd::Zero(num_elements_);
  for (const Eigen::MatrixXd& m : changes)
    for (int e = 0; e < num_elements_; ++e)
      reach[e] = std::max(reach[e], m.middleRows<kStrainComponents>(kStrainComponents * e).cwiseAbs().maxCoeff());
  const double cut = prune_relative * reach.maxCoeff();
  std::vector<int> compact(size_t(num_elements_), -1), active;
  for (int e = 0; e < num_elements_; ++e)
    if (reach[e] > cut || cut == 0) compact[size_t(e)] = int(active.size()), active.push_back(e);
  const Eigen::Index rows = kStrainComponents * Eigen::Index(active.size());
  auto gather = [&](const Eigen::MatrixXd& m) {
    Eigen::MatrixXd out(rows, m.cols());
    for (size_t a = 0; a < active.size(); ++a)
      out.middleRows<kStrainComponents>(kStrainComponents * Eigen::Index(a)) = m.middleRows<kStrainComponents>(kStrainComponents * active[a]);
    return out;
  };
  preload_strain_ = gather(in.preload_strain);
  mu_Pa_.resize(Eigen::Index(active.size())), lambda_Pa_.resize(Eigen::Index(active.size()));
  for (size_t a = 0; a < active.size(); ++a) mu_Pa_[Eigen::Index(a)] = in.mu_Pa[active[a]], lambda_Pa_[Eigen::Index(a)] = in.lambda_Pa[active[a]];
  knot_command_ = in.knot_command;
  for (const Eigen::MatrixXd& m : in.strain_at_knot) strain_at_knot_.push_back(gather(m));
  // Segment k's slope, from the strain at its start (0 at v = 0) to the strain at knot k.
  for (size_t k = 0; k < knot_command_.size(); ++k) {
    const double v0 = k ? knot_command_[k - 1] : 0.0;
    const Eigen::MatrixXd start = k ? strain_at_knot_[k - 1] : Eigen::MatrixXd::Zero(rows, num_actuators_);
    slope_.push_back((strain_at_knot_[k] - start) / (knot_command_[k] - v0));
  }
  if (knot_command_.empty()) slope_.push_back(gather(in.strain_per_command));
  // Segment k >= 1's intercept, eps(knot k-1) - knot_{k-1} slope_k, in single precision like
  // the slopes (a strain change; the preload stays double in intercept_): a segment change
  // then reads one float column instead of two double ones.
  for (size_t k = 1; k <= knot_command_.size(); ++k)
    tables.knot_intercept.push_back((strain_at_knot_[k - 1] - knot_command_[k - 1] * slope_[std::min(k, slope_.size() - 1)]).cast<float>());
  // Each slope, per actuator, in the kernel's chunk layout: a segment change copies blocks.
  const size_t chunks = SedChunks(active.size());
  for (const Eigen::MatrixXd& slope : slope_) {
    std::vector<float> blocks(size_t(num_actuators_) * chunks * kStrainComponents * kSedLanes, 0.0f);
    for (int i = 0; i < num_actuators_; ++i)
      for (size_t e = 0; e < active.size(); ++e)
        for (int c = 0; c < kStrainComponents; ++c)
          blocks[((size_t(i) * chunks + e / kSedLanes) * kStrainComponents + size_t(c)) * kSedLanes + e % kSedLanes] =
              float(slope(Eigen::Index(kStrainComponents * e + size_t(c)), i));
    tables.chunked_slope.push_back(std::move(blocks));
  }
  effective_.assign(SedChunks(active.size()) * size_t(num_actuators_) * kStrainComponents * kSedLanes, 0.0f);
  slope_index_.assign(size_t(num_actuators_), -1);
  segment_.assign(size_t(num_actuators_), 0);
  intercept_segment_.clear();  // none built yet
  stroke_.setZero(num_actuators_);
  // The vertex average over the active elements, for the vertices that have any; the
  // pruned elements keep the preload's SED.
  const int vertices = int(in.vertex_start.size()) - 1;
  fixed_sed_Pa_.setZero(vertices);
  active_vertex_.clear(), vertex_start_.assign(1, 0), vertex_element_.clear(), vertex_weight_.clear();
  for (int v = 0; v < vertices; ++v) {
    const size_t first = vertex_element_.size();
    for (int k = in.vertex_start[size_t(v)]; k < in.vertex_start[size_t(v) + 1]; ++k) {
      const int e = in.vertex_element[size_t(k)];
      if (compact[size_t(e)] >= 0) {
        vertex_element_.push_back(compact[size_t(e)]);
        vertex_weight_.push_back(in.vertex_weight[size_t(k)]);
        continue;
      }
      const double* eps = in.preload_strain.data() + kStrainComponents * e;
      double w = 0;
      fem::SymmetricStrainSed<double>(eps[0], eps[1], eps[2], eps[3], eps[4], eps[5], in.mu_Pa[e], in.lambda_Pa[e], w);
      fixed_sed_Pa_[v] += in.vertex_weight[size_t(k)] * w;
    }
    if (vertex_element_.size() == first) continue;
    active_vertex_.push_back(v);
    vertex_start_.push_back(int(vertex_element_.size()));
  }
}

int DisplayInfluence::SegmentOf(double v) const {
  int k = 0;
  while (size_t(k) < knot_command_.size() && v >= knot_command_[size_t(k)]) ++k;
  return k;
}

void DisplayInfluence::Segments(const Eigen::VectorXd& u) const {
  const int n = num_actuators_;
  for (int i = 0; i < n; ++i) {
    // Linear: every actuator, any sign, on its one slope. Piecewise: nothing below the
    // offset (v = 0 takes the first segment's slope for the derivative); segment k starts
    // at 0 (k = 0) or at knot k-1 with that knot's strain; past the last knot the last
    // slope goes on.
    const double v = piecewise_ ? u[i] - offset_[i] : u[i];
    const bool moving = !piecewise_ || v > 0;
    const int k = moving && piecewise_ ? SegmentOf(v) : 0;
    const int slope = moving || v == 0 ? std::min(k, int(tables_->chunked_slope.size()) - 1) : -1;
    segment_[size_t(i)] = moving ? k : -1;
    stroke_[i] = moving ? v : 0.0;
    if (slope == slope_index_[size_t(i)]) continue;
    slope_index_[size_t(i)] = slope;
    constexpr size_t block = kStrainComponents * kSedLanes;
    const size_t chunks = SedChunks(size_t(mu_Pa_.size()));
    for (size_t b = 0; b < chunks; ++b) {
      float* to = effective_.data() + (b * size_t(n) + size_t(i)) * block;
      if (slope < 0) {
        std::fill(to, to + block, 0.0f);
        continue;
      }
      const float* from = tables_->chunked_slope[size_t(slope)].data() + (size_t(i) * chunks + b) * block;
      std::copy(from, from + block, to);
    }
  }
  // The strain at v on segment k >= 1 is eps(knot k-1) + (v - knot) slope_k = intercept +
  // v slope_k. The intercept is kept up to date with the actuators whose segment changed
  // (on a 64-pin display a full sum streams 64 columns of the layer's strain), and summed
  // afresh every kInterceptRefresh updates so that rounding cannot creep.
  if (segment_ == intercept_segment_) return;
  constexpr int kInterceptRefresh = 256;
  const bool fresh = intercept_segment_.size() != segment_.size() || ++intercept_updates_ >= kInterceptRefresh;
  if (fresh) {
    intercept_ = preload_strain_;
    intercept_updates_ = 0;
  }
  for (int i = 0; i < n; ++i) {
    const int k = segment_[size_t(i)], was = fresh ? 0 : intercept_segment_[size_t(i)];
    if (k == was || (k < 1 && was < 1)) continue;  // segments 0 and below have no intercept
    if (was >= 1 && k >= 1)
      intercept_ += (tables_->knot_intercept[size_t(k - 1)].col(i) - tables_->knot_intercept[size_t(was - 1)].col(i)).cast<double>();
    else if (k >= 1)
      intercept_ += tables_->knot_intercept[size_t(k - 1)].col(i).cast<double>();
    else
      intercept_ -= tables_->knot_intercept[size_t(was - 1)].col(i).cast<double>();
  }
  intercept_segment_ = segment_;
}

void DisplayInfluence::ElementSeds(const Eigen::VectorXd& u, bool gradient) const {
  Segments(u);
  const Eigen::Index elements = mu_Pa_.size(), n = num_actuators_;
  stroke_f_ = stroke_.cast<float>();
  element_sed_.resize(elements);
  if (gradient) element_gradient_t_.resize(n, elements);
  scratch_.resize(size_t(n) * kSedLanes);
  ChunkedElementSeds(size_t(elements), int(n), effective_.data(), stroke_f_.data(), intercept_.data(), mu_Pa_.data(),
                     lambda_Pa_.data(), element_sed_.data(), gradient ? element_gradient_t_.data() : nullptr,
                     scratch_.data());
}

void DisplayInfluence::FormSeds(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa, Eigen::MatrixXd* jacobian_t) const {
  const size_t active = active_vertex_.size();
  stroke_f_ = u.cast<float>();
  scratch_.resize(size_t(num_actuators_) * kSedLanes);
  sed_Pa.resize(Eigen::Index(active));
  if (jacobian_t) jacobian_t->resize(num_actuators_, Eigen::Index(active));
  VertexFormSeds(active, num_actuators_, tables_->vertex_forms.data(), vertex_constant_.data(), stroke_f_.data(), sed_Pa.data(),
                 jacobian_t ? jacobian_t->data() : nullptr, scratch_.data());
}

void DisplayInfluence::AverageToActiveVertices(Eigen::VectorXd& vertex) const {
  const size_t active = active_vertex_.size();
  vertex.resize(Eigen::Index(active));
  for (size_t a = 0; a < active; ++a) {
    double s = fixed_sed_Pa_[active_vertex_[a]];
    for (int k = vertex_start_[a]; k < vertex_start_[a + 1]; ++k)
      s += vertex_weight_[size_t(k)] * element_sed_[vertex_element_[size_t(k)]];
    vertex[Eigen::Index(a)] = s;
  }
}

void DisplayInfluence::BuildVertexForms(Tables& tables) {
  // W(eps) = 1/2 eps^T D eps with D = 2 mu diag(1, 1, 1, 2, 2, 2) + lambda 1 1^T on the normal
  // components (the shear ones count twice in eps:eps), so W(eps0 + E u) = W(eps0) +
  // (E^T D eps0) . u + u^T (1/2 E^T D E) u, summed over the vertex's elements.
  const int n = num_actuators_;
  const size_t active = active_vertex_.size(), full = VertexFormEntries(n);
  const Eigen::MatrixXd& slope = slope_.front();
  tables.vertex_forms.assign(SedChunks(active) * full * kSedLanes, 0.0f);  // VertexFormSeds' chunks (padding 0)
  vertex_constant_.setZero(Eigen::Index(active));
  Eigen::VectorXd g(n);
  Eigen::MatrixXd Q(n, n);
  for (size_t a = 0; a < active; ++a) {
    double constant = fixed_sed_Pa_[active_vertex_[a]];
    g.setZero(), Q.setZero();
    for (int k = vertex_start_[a]; k < vertex_start_[a + 1]; ++k) {
      const int e = vertex_element_[size_t(k)];
      const double w = vertex_weight_[size_t(k)], mu = mu_Pa_[e], lambda = lambda_Pa_[e];
      Eigen::Matrix<double, kStrainComponents, kStrainComponents> D = Eigen::Matrix<double, kStrainComponents, kStrainComponents>::Zero();
      for (int c = 0; c < 3; ++c) D(c, c) = 2.0 * mu, D(c + 3, c + 3) = 4.0 * mu;
      D.topLeftCorner<3, 3>().array() += lambda;
      const auto eps0 = preload_strain_.segment<kStrainComponents>(kStrainComponents * e);
      const auto E = slope.middleRows<kStrainComponents>(kStrainComponents * e);
      constant += w * 0.5 * eps0.dot(D * eps0);
      g += w * (E.transpose() * (D * eps0));
      Q += w * 0.5 * (E.transpose() * D * E);
    }
    vertex_constant_[Eigen::Index(a)] = constant;
    for (int i = 0; i < n; ++i) tables.vertex_forms[VertexFormIndex(a, size_t(i), n)] = float(g[i]);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) tables.vertex_forms[VertexFormIndex(a, size_t(n + i * n + j), n)] = float(Q(j, i));
  }
}

void DisplayInfluence::ActiveSed(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa) const {
  if (tables_ && !tables_->vertex_forms.empty()) {
    FormSeds(u, sed_Pa, nullptr);
    return;
  }
  ElementSeds(u, false);
  AverageToActiveVertices(sed_Pa);
}

void DisplayInfluence::ActiveSedAndJacobianT(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa,
                                             Eigen::MatrixXd& jacobian_t) const {
  if (tables_ && !tables_->vertex_forms.empty()) {
    FormSeds(u, sed_Pa, &jacobian_t);
    return;
  }
  ElementSeds(u, true);
  AverageToActiveVertices(sed_Pa);
  const size_t active = active_vertex_.size();
  jacobian_t.resize(num_actuators_, Eigen::Index(active));
  Eigen::VectorXf sum(num_actuators_);
  for (size_t a = 0; a < active; ++a) {
    sum.setZero();
    for (int k = vertex_start_[a]; k < vertex_start_[a + 1]; ++k)
      sum += float(vertex_weight_[size_t(k)]) * element_gradient_t_.col(vertex_element_[size_t(k)]);
    jacobian_t.col(Eigen::Index(a)) = sum.cast<double>();
  }
}

void DisplayInfluence::Sed(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa) const {
  ActiveSed(u, active_sed_);
  sed_Pa = fixed_sed_Pa_;
  for (size_t a = 0; a < active_vertex_.size(); ++a) sed_Pa[active_vertex_[a]] = active_sed_[Eigen::Index(a)];
}

void DisplayInfluence::SedAndJacobian(const Eigen::VectorXd& u, Eigen::VectorXd& sed_Pa, Eigen::MatrixXd& jacobian) const {
  ActiveSedAndJacobianT(u, active_sed_, active_jacobian_t_);
  sed_Pa = fixed_sed_Pa_;
  jacobian.setZero(num_vertices(), num_actuators_);
  for (size_t a = 0; a < active_vertex_.size(); ++a) {
    sed_Pa[active_vertex_[a]] = active_sed_[Eigen::Index(a)];
    jacobian.row(active_vertex_[a]) = active_jacobian_t_.col(Eigen::Index(a)).transpose();
  }
}

}  // namespace sedbridge::render
