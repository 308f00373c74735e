#include "fem/compliance_sed_map.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "fem/column_products.h"
#include "fem/tet_sed.h"

namespace sedbridge::fem {

using column_products::AddColumnsByRowBlocks;
using column_products::AddKeptColumnsByRowBlocks;
using column_products::ForEachRowBlock;
using column_products::SetThreeColumns;

ComplianceSedMap::ComplianceSedMap(const ElasticTetForce& elastic, std::vector<int> vertices,
                                   ComplianceSedMapOptions options)
    : options_(options), sed_(std::make_unique<VertexSedEvaluator>(elastic, std::move(vertices))) {
  const TetMesh& mesh = elastic.mesh();
  sed_nodes_ = sed_->element_nodes();
  std::vector<int> local(size_t(mesh.num_nodes()), -1);
  for (size_t a = 0; a < sed_nodes_.size(); ++a) local[size_t(sed_nodes_[a])] = int(a);
  const std::vector<int>& elements = sed_->elements();
  const size_t count = elements.size();
  offset_.assign(4 * count, 0);
  gradient_.assign(12 * count, 0.0);
  mu_Pa_.resize(count);
  lambda_Pa_.resize(count);
  for (size_t k = 0; k < count; ++k) {
    const int e = elements[k];
    const TetElement& te = elastic.elements()[size_t(e)];
    for (size_t a = 0; a < 4; ++a) {
      offset_[a * count + k] = 3 * local[size_t(mesh.tets[size_t(e)][a])];
      for (size_t q = 0; q < 3; ++q) gradient_[(3 * a + q) * count + k] = te.shape_gradients(Eigen::Index(a), Eigen::Index(q));
    }
    mu_Pa_[k] = te.mu_Pa;
    lambda_Pa_[k] = te.lambda_Pa;
  }
  u_s_m_ = Eigen::VectorXd::Zero(Eigen::Index(3 * sed_nodes_.size()));
}

ComplianceSedMap::~ComplianceSedMap() = default;

const std::vector<int>& ComplianceSedMap::vertices() const { return sed_->vertices(); }

void ComplianceSedMap::BindOperator(const Eigen::MatrixXd& G_m_N) {
  G_single_ = G_m_N.cast<float>();
  // Kept columns within the budget (as a double first: a huge budget must not overflow the
  // cast; one that is not a positive size keeps none).
  const double rows = double(G_single_.rows()), nodes = double(G_single_.cols() / 3);
  const double MiB = options_.kept_columns_MiB;
  kept_budget_ = MiB > 0 && rows > 0 ? Eigen::Index(std::min(std::floor(MiB * 1048576.0 / (4.0 * rows)), nodes)) : 0;
  if (kept_budget_ > 0) direction_.resize(size_t(nodes));
}

void ComplianceSedMap::BeginForces(Eigen::Index count) {
  kept_slots_.clear();
  kept_coefficients_.clear();
  triple_columns_.clear();
  forces_.resize(3, count);
}

void ComplianceSedMap::AddNodeForce(int candidate, const Eigen::Vector3d& f) {
  double coefficient = 0;
  const int slot = KeptColumn(candidate, f, &coefficient);
  if (slot >= 0) {
    kept_slots_.push_back(slot);
    kept_coefficients_.push_back(coefficient);
  } else {
    forces_.col(Eigen::Index(triple_columns_.size())) = f;
    triple_columns_.push_back(candidate);
  }
}

const Eigen::VectorXd& ComplianceSedMap::ComputeDisplacements() {
  u_s_m_.setZero();
  kept_reads_ += kept_slots_.size();
  const double entries = double(G_single_.rows()) * (3.0 * double(triple_columns_.size()) + double(kept_slots_.size()));
  const int team = entries >= options_.parallel_min_entries ? omp_get_max_threads() : 1;
  AddColumnsByRowBlocks(G_single_, triple_columns_, forces_, team, u_s_m_);
  AddKeptColumnsByRowBlocks(kept_, kept_slots_, kept_coefficients_, team, u_s_m_);
  return u_s_m_;
}

void ComplianceSedMap::ComputeSed(Eigen::VectorXd& vertex_sed_Pa) {
  // Linear SED straight from the displacement gradient (ElementSed with R = I, a third of
  // its work: most of a step with few contacts).
  const int count = int(mu_Pa_.size());
  element_sed_Pa_.resize(count);
  const int team = count >= options_.parallel_min_elements ? omp_get_max_threads() : 1;
  ForEachRowBlock(count, team, [&](Eigen::Index begin, Eigen::Index end) {
    LinearTetSeds(int(begin), int(end), count, offset_.data(), gradient_.data(), mu_Pa_.data(), lambda_Pa_.data(),
                  u_s_m_.data(), element_sed_Pa_.data());
  });
  sed_->AverageToVertices(element_sed_Pa_, vertex_sed_Pa);
}

void ComplianceSedMap::ElementStrains(const Eigen::VectorXd& u, Eigen::VectorXd& strain) const {
  const int count = int(mu_Pa_.size());
  strain.resize(6 * Eigen::Index(count));
  for (int e = 0; e < count; ++e) {
    double H[3][3] = {};  // displacement gradient sum_a u_a g_a^T
    for (int a = 0; a < 4; ++a) {
      const double* ua = u.data() + offset_[size_t(a * count + e)];
      for (int q = 0; q < 3; ++q) {
        const double g = gradient_[size_t((3 * a + q) * count + e)];
        for (int r = 0; r < 3; ++r) H[r][q] += ua[r] * g;
      }
    }
    double* s = strain.data() + 6 * Eigen::Index(e);
    s[0] = H[0][0], s[1] = H[1][1], s[2] = H[2][2];
    s[3] = 0.5 * (H[0][1] + H[1][0]), s[4] = 0.5 * (H[0][2] + H[2][0]), s[5] = 0.5 * (H[1][2] + H[2][1]);
  }
}

void ComplianceSedMap::VertexAverage(std::vector<int>& start, std::vector<int>& element, std::vector<double>& weight) const {
  // The evaluator's average is linear in the element SEDs: read it off unit fields.
  const Eigen::Index elements = Eigen::Index(mu_Pa_.size()), vertices = Eigen::Index(sed_->vertices().size());
  std::vector<std::vector<std::pair<int, double>>> rows;
  rows.resize(size_t(vertices));
  Eigen::VectorXd unit = Eigen::VectorXd::Zero(elements), vertex;
  for (Eigen::Index e = 0; e < elements; ++e) {
    unit[e] = 1.0;
    sed_->AverageToVertices(unit, vertex);
    unit[e] = 0.0;
    for (Eigen::Index v = 0; v < vertices; ++v)
      if (vertex[v] != 0) rows[size_t(v)].push_back({int(e), vertex[v]});
  }
  start.assign(1, 0);
  element.clear();
  weight.clear();
  for (const auto& row : rows) {
    for (const auto& [e, w] : row) element.push_back(e), weight.push_back(w);
    start.push_back(int(element.size()));
  }
}

int ComplianceSedMap::KeptColumn(int node, const Eigen::Vector3d& f, double* coefficient) {
  const Eigen::Index rows = G_single_.rows();
  const double size = f.norm();
  if (kept_budget_ <= 0 || !(size > 0)) return -1;
  KeptDirection& d = direction_[size_t(node)];
  const double along = f.dot(d.dir);
  if (!((f - along * d.dir).norm() <= 1e-12 * size)) {  // turned (or first seen): remember where
    if (d.slot >= 0) kept_free_.push_back(d.slot);
    d.slot = -1;
    d.dir = f / size;
    return -1;
  }
  if (d.slot < 0) {  // the second time along d: keep G(:, node) d
    if (!kept_free_.empty()) {
      d.slot = kept_free_.back();
      kept_free_.pop_back();
    } else if (kept_.cols() < kept_budget_) {
      // Grow in steps (a plane's patch arrives in a step or two), keeping what is there.
      const Eigen::Index cols = kept_.cols();
      const Eigen::Index grown = std::min<Eigen::Index>(kept_budget_, std::max<Eigen::Index>(32, 2 * cols));
      kept_.conservativeResize(rows, grown);
      for (Eigen::Index slot = grown - 1; slot > cols; --slot) kept_free_.push_back(int(slot));
      d.slot = int(cols);
    } else {
      return -1;  // out of the budget: three columns
    }
    // From G's float columns as the three-column product reads them, summed in double and
    // stored in single precision as G is (ComplianceContact.KeptSedColumnsGiveTheThreeColumnSed:
    // the same SED to 1e-6).
    const float* g = G_single_.data() + 3 * Eigen::Index(node) * rows;
    SetThreeColumns(int(rows), g, g + rows, g + 2 * rows, d.dir[0], d.dir[1], d.dir[2], kept_.col(d.slot).data());
    ++columns_kept_;
  }
  *coefficient = along;
  return d.slot;
}

}  // namespace sedbridge::fem
