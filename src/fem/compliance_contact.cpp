#include "fem/compliance_contact.h"

#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <stdexcept>
#include <utility>

#include "common/hot_clones.h"
#include "fem/column_products.h"
#include "fem/elastic_tet_force.h"
#include "fem/linear_solver.h"
#include "fem/system_matrix.h"

namespace sedbridge::fem {

using column_products::AddColumns3;
using column_products::AddColumnsByRowBlocks;
using column_products::AddKeptColumnsByRowBlocks;
using column_products::AddThreeColumns;
using column_products::ForEachRowBlock;
using column_products::SetThreeColumns;

namespace {

// Exact contact: compliance added to the contact Newton matrix, relative to its largest
// diagonal entry [-]. Far below any physical compliance (the answer does not move), large
// enough to keep the matrix definite when two contacts push one node along dependent normals.
constexpr double kExactContactRegularization = 1e-12;
// Floor of the largest contact force used to scale the penalty gap tolerance [N]: before any
// force is known the tolerance must still be positive.
constexpr double kMinForceScale_N = 1e-12;

// Bump when the cache layout or the meaning of W/G changes: old files then stop matching.
constexpr std::uint64_t kCacheVersion = 1;
// Exact contact's gap tolerance is relative_tolerance times this length.
constexpr double kExactGapScale_m = 1e-3;
// A point whose gap is known to exceed this is not evaluated again within a step (it can
// only come into contact by moving that far; the QP sees the bound as its gap).
constexpr double kFarGap_m = 0.5e-3;
// Force control: a row whose direction turns less than this [-] toward the push cannot
// start carrying the force (its force would be huge, its gap closing from far away).
constexpr double kMinPush = 1e-3;
constexpr char kCacheMagic[8] = {'S', 'E', 'D', 'B', 'W', 'C', 'M', 'P'};

// FNV-1a, 64 bit: a content key for the cache (not a security hash).
struct Fnv {
  std::uint64_t h = 1469598103934665603ull;
  void Bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  }
  template <typename T>
  void Pod(const T& v) { Bytes(&v, sizeof v); }
  template <typename T>
  void Vector(const std::vector<T>& v) {
    Pod(std::uint64_t(v.size()));
    Bytes(v.data(), v.size() * sizeof(T));
  }
};

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

// The Merkel layer's linear SED, a hot loop of a step (the other: the dense column products,
// fem/column_products.h) as a raw-pointer function with an AVX2 clone (common/hot_clones.h).
// Linear SED of tetrahedra [begin, end) of `count` from the displacements u [m] of their
// nodes: element e's node a at u + offset[a * count + e], shape gradient component (a, q) at
// gradient[(3 a + q) * count + e] (structure of arrays, so the loop vectorizes across
// elements). mu eps:eps + lambda/2 tr(eps)^2 [Pa].
SEDBRIDGE_HOT_CLONES
void LinearElementSeds(int begin, int end, int count, const int* offset, const double* gradient, const double* mu_Pa,
                       const double* lambda_Pa, const double* u, double* sed_Pa) {
#pragma omp simd
  for (int e = begin; e < end; ++e) {
    double H[3][3] = {};  // displacement gradient sum_a u_a g_a^T
    for (int a = 0; a < 4; ++a) {
      const double* ua = u + offset[a * count + e];
      for (int q = 0; q < 3; ++q) {
        const double g = gradient[(3 * a + q) * count + e];
        for (int r = 0; r < 3; ++r) H[r][q] += ua[r] * g;
      }
    }
    const double e01 = 0.5 * (H[0][1] + H[1][0]), e02 = 0.5 * (H[0][2] + H[2][0]), e12 = 0.5 * (H[1][2] + H[2][1]);
    const double tr = H[0][0] + H[1][1] + H[2][2];
    const double eps_eps = H[0][0] * H[0][0] + H[1][1] * H[1][1] + H[2][2] * H[2][2] + 2 * (e01 * e01 + e02 * e02 + e12 * e12);
    sed_Pa[e] = mu_Pa[e] * eps_eps + 0.5 * lambda_Pa[e] * tr * tr;
  }
}

}  // namespace

ComplianceContact::ComplianceContact(const TetMesh& mesh, std::vector<std::unique_ptr<ForceTerm>> terms,
                                     std::vector<int> candidate_nodes, std::vector<int> sed_vertices,
                                     ComplianceContactOptions options)
    : mesh_(mesh), terms_(std::move(terms)), candidates_(std::move(candidate_nodes)), options_(std::move(options)) {
  const auto t0 = std::chrono::steady_clock::now();
  const ElasticTetForce* elastic = nullptr;
  for (const auto& t : terms_) {
    if (!t->JacobianIsConstant())
      throw std::invalid_argument("compliance contact: term '" + t->name() + "' has a non-constant Jacobian");
    if (!elastic) elastic = dynamic_cast<const ElasticTetForce*>(t.get());
  }
  if (options_.exact_contact && options_.friction_anisotropy > 0)
    throw std::invalid_argument("compliance contact: pseudo friction needs the penalty law (not exact_contact)");
  if (!elastic || elastic->formulation() != ElasticFormulation::kLinear)
    throw std::invalid_argument("compliance contact needs a linear elastic term (the compliance is K^-1 at rest)");
  const int n = mesh.num_nodes();
  {
    std::set<int> unique(candidates_.begin(), candidates_.end());
    if (unique.size() != candidates_.size() || (!unique.empty() && (*unique.begin() < 0 || *unique.rbegin() >= n)))
      throw std::invalid_argument("compliance contact: candidate nodes must be unique mesh nodes");
  }
  for (const ContactSample& sample : options_.face_samples) {
    double sum = 0;
    for (int a = 0; a < 3; ++a) {
      const double w = sample.weight[size_t(a)];
      if (sample.candidate[size_t(a)] < 0 || sample.candidate[size_t(a)] >= int(candidates_.size()) ||
          !(w >= 0) || !std::isfinite(w))
        throw std::invalid_argument("compliance contact: a face sample needs candidate indices and weights >= 0");
      sum += w;
    }
    if (!(std::abs(sum - 1.0) <= 1e-9))
      throw std::invalid_argument("compliance contact: a face sample's weights must sum to 1");
  }
  sed_ = std::make_unique<VertexSedEvaluator>(*elastic, std::move(sed_vertices));
  {
    sed_nodes_ = sed_->element_nodes();
    std::vector<int> local(size_t(n), -1);
    for (size_t a = 0; a < sed_nodes_.size(); ++a) local[size_t(sed_nodes_[a])] = int(a);
    const std::vector<int>& elements = sed_->elements();
    const size_t count = elements.size();
    sed_offset_.assign(4 * count, 0);
    sed_gradient_.assign(12 * count, 0.0);
    sed_mu_Pa_.resize(count);
    sed_lambda_Pa_.resize(count);
    for (size_t k = 0; k < count; ++k) {
      const int e = elements[k];
      const TetElement& te = elastic->elements()[size_t(e)];
      for (size_t a = 0; a < 4; ++a) {
        sed_offset_[a * count + k] = 3 * local[size_t(mesh.tets[size_t(e)][a])];
        for (size_t q = 0; q < 3; ++q) sed_gradient_[(3 * a + q) * count + k] = te.shape_gradients(Eigen::Index(a), Eigen::Index(q));
      }
      sed_mu_Pa_[k] = te.mu_Pa;
      sed_lambda_Pa_[k] = te.lambda_Pa;
    }
  }

  // K at rest from the model's own terms (quasi-static: stiffness only).
  SystemMatrix K;
  std::vector<std::pair<int, int>> pairs;
  for (const auto& t : terms_) t->AppendCoupledNodes(pairs);
  K.Build(n, pairs);
  for (const auto& t : terms_) t->BindMatrix(K);
  K.SetZero();
  x_.resize(3 * n);
  for (int i = 0; i < n; ++i) x_.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(3 * n);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * n);
  JacobianSink sink{&K, 1.0, 0.0};
  const SystemState rest{x_, v, 0.0, false};
  for (const auto& t : terms_) t->AddForce(rest, f, &sink);

  // The key covers everything W and G depend on: K (mesh, materials, supports), which
  // nodes are candidates and which the SED reads.
  Fnv key;
  key.Pod(kCacheVersion);
  key.Pod(std::int64_t(n));
  const auto& csr = K.csr();
  key.Bytes(csr.outerIndexPtr(), size_t(csr.outerSize() + 1) * sizeof(int));
  key.Bytes(csr.innerIndexPtr(), size_t(csr.nonZeros()) * sizeof(int));
  key.Bytes(csr.valuePtr(), size_t(csr.nonZeros()) * sizeof(double));
  key.Vector(candidates_);
  key.Vector(sed_nodes_);

  if (!options_.cache_dir.empty()) {
    char name[64];
    std::snprintf(name, sizeof name, "compliance_%016llx.bin", static_cast<unsigned long long>(key.h));
    cache_file_ = (std::filesystem::path(options_.cache_dir) / name).string();
  }
  loaded_from_cache_ = !cache_file_.empty() && !options_.full_field && LoadCache(key.h);
  if (!loaded_from_cache_) {
    Precompute(K);
    if (!cache_file_.empty()) SaveCache(key.h);
  }

  const int c = int(candidates_.size());
  rest_c_.resize(3, c);
  for (int j = 0; j < c; ++j) rest_c_.col(j) = mesh.rest_positions_m.col(candidates_[size_t(j)]);
  sample_node_ = candidates_;
  node_force_ = node_u_ = Eigen::VectorXd::Zero(3 * c);
  node_forced_.assign(size_t(c), 0);
  if (!options_.face_samples.empty()) AddFaceSamples();
  // The SED's map in single precision: half the bytes a step reads (G is 20 MB on B, far
  // larger than a core's L2 cache) for ~1e-7 relative in the SED nodes' displacements. (W
  // stays double: the contact iteration compares its products with the QP's prediction.)
  G_single_ = G_.cast<float>();
  {
    // Kept SED columns within the budget (as a double first: a huge budget must not
    // overflow the cast; one that is not a positive size keeps none).
    const double rows = double(G_single_.rows()), nodes = double(G_single_.cols() / 3);
    const double MiB = options_.sed_kept_columns_MiB;
    sed_kept_budget_ = MiB > 0 && rows > 0 ? Eigen::Index(std::min(std::floor(MiB * 1048576.0 / (4.0 * rows)), nodes)) : 0;
    if (sed_kept_budget_ > 0) sed_direction_.resize(size_t(nodes));
  }
  f_c_ = u_c_ = u_t_ = Eigen::VectorXd::Zero(3 * num_samples());
  u_s_ = Eigen::VectorXd::Zero(Eigen::Index(3 * sed_nodes_.size()));
  ResetWarmStart();
  precompute_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

ComplianceContact::~ComplianceContact() = default;

void ComplianceContact::AddFaceSamples() {
  const int c = int(candidates_.size()), e = int(options_.face_samples.size()), S = c + e;
  // B: S x c interpolation (the nodes' rows the identity); W over the samples is B W B^T
  // (the QP reads its 3x3 blocks; products go through the nodes, AddWTimes).
  auto right = [&](const Eigen::MatrixXd& M) {  // M B^T
    Eigen::MatrixXd out(M.rows(), 3 * S);
    out.leftCols(3 * c) = M;
    for (int k = 0; k < e; ++k) {
      const ContactSample& sample = options_.face_samples[size_t(k)];
      auto block = out.middleCols<3>(3 * (c + k));
      block.setZero();
      for (int a = 0; a < 3; ++a) block += sample.weight[size_t(a)] * M.middleCols<3>(3 * sample.candidate[size_t(a)]);
    }
    return out;
  };
  // W is symmetric, so (W B^T)^T = B W and B W B^T = right(right(W)^T).
  Eigen::MatrixXd BWB = right(right(W_).transpose());
  W_nodes_ = std::move(W_);
  W_ = 0.5 * (BWB + BWB.transpose());
  rest_c_.conservativeResize(3, S);
  sample_node_.resize(size_t(S));
  for (int k = 0; k < e; ++k) {
    const ContactSample& sample = options_.face_samples[size_t(k)];
    rest_c_.col(c + k).setZero();
    for (int a = 0; a < 3; ++a) rest_c_.col(c + k) += sample.weight[size_t(a)] * rest_c_.col(sample.candidate[size_t(a)]);
    sample_node_[size_t(c + k)] = candidates_[size_t(sample.candidate[0])];
  }
}

const std::vector<int>& ComplianceContact::sed_vertices() const { return sed_->vertices(); }

void ComplianceContact::AddSampleForce(int j, const Eigen::Vector3d& f) const {
  const int c = int(candidates_.size());
  auto add = [&](int node, const Eigen::Vector3d& g) {
    if (!node_forced_[size_t(node)]) {
      node_forced_[size_t(node)] = 1;
      forced_nodes_.push_back(node);
    }
    node_force_.segment<3>(3 * node) += g;
  };
  if (j < c) {
    add(j, f);
    return;
  }
  const ContactSample& sample = options_.face_samples[size_t(j - c)];
  for (int a = 0; a < 3; ++a) add(sample.candidate[size_t(a)], sample.weight[size_t(a)] * f);
}

template <typename Take>
void ComplianceContact::TakeNodeForces(const Take& take) const {
  for (int node : forced_nodes_) {
    take(node, Eigen::Vector3d(node_force_.segment<3>(3 * node)));
    node_force_.segment<3>(3 * node).setZero();
    node_forced_[size_t(node)] = 0;
  }
  forced_nodes_.clear();
}

template <typename Matrix>
void ComplianceContact::ApplyNodeForces(const Matrix& A, Eigen::VectorXd& y) const {
  TakeNodeForces([&](int node, const Eigen::Vector3d& f) { AddColumns3(A, node, f, y); });
}

void ComplianceContact::AddToSamples(const Eigen::VectorXd& u_nodes, Eigen::VectorXd& u_samples) const {
  const int c = int(candidates_.size());
  u_samples.head(3 * c) += u_nodes;
  for (size_t k = 0; k < options_.face_samples.size(); ++k) {
    const ContactSample& sample = options_.face_samples[k];
    auto u = u_samples.segment<3>(3 * (c + Eigen::Index(k)));
    for (int a = 0; a < 3; ++a) u += sample.weight[size_t(a)] * u_nodes.segment<3>(3 * sample.candidate[size_t(a)]);
  }
}

template <typename Items, typename SampleOf, typename Force>
void ComplianceContact::AddWTimes(const Items& items, const SampleOf& sample_of, const Force& force,
                                  Eigen::VectorXd& u_samples) {
  if (options_.face_samples.empty()) {
    for (int item : items) {
      const Eigen::Vector3d f = force(item);
      if (!f.isZero(0.0)) AddColumns3(W_, sample_of(item), f, u_samples);
    }
    return;
  }
  for (int item : items) {
    const Eigen::Vector3d f = force(item);
    if (!f.isZero(0.0)) AddSampleForce(sample_of(item), f);
  }
  if (forced_nodes_.empty()) return;  // no force (a press without shear: the tangential part)
  node_u_.setZero();
  ApplyNodeForces(W_nodes_, node_u_);
  AddToSamples(node_u_, u_samples);
}

Eigen::Map<const Eigen::Matrix3Xd> ComplianceContact::candidate_displacements_m() const {
  return {u_c_.data(), 3, Eigen::Index(candidates_.size())};
}

void ComplianceContact::Precompute(const SystemMatrix& K) {
  DirectLdltSolver solver;
  solver.Prepare(K);
  const int c = int(candidates_.size());
  const int s = int(sed_nodes_.size());
  W_.resize(3 * c, 3 * c);
  G_.resize(3 * s, 3 * c);
  if (options_.full_field) F_.resize(3 * K.num_nodes(), 3 * c);
  bool ok = true;
  const int threads = options_.precompute_threads > 0 ? options_.precompute_threads : omp_get_max_threads();
  // One back-substitution per candidate dof (column of K^-1 H^T); columns are independent.
  // DirectLdltSolver::Solve only reads the factor, so threads may share it.
#pragma omp parallel num_threads(threads) reduction(&& : ok)
  {
    Eigen::VectorXd b = Eigen::VectorXd::Zero(K.num_nodes() * 3), x;
#pragma omp for schedule(dynamic, 8)
    for (int col = 0; col < 3 * c; ++col) {
      const int dof = 3 * candidates_[size_t(col / 3)] + col % 3;
      b[dof] = 1.0;
      x.setZero(b.size());
      const LinearSolveReport r = solver.Solve(K, b, x);
      b[dof] = 0.0;
      ok = ok && r.converged && x.allFinite();
      for (int j = 0; j < c; ++j) W_.block<3, 1>(3 * j, col) = x.segment<3>(3 * candidates_[size_t(j)]);
      for (int j = 0; j < s; ++j) G_.block<3, 1>(3 * j, col) = x.segment<3>(3 * sed_nodes_[size_t(j)]);
      if (options_.full_field) F_.col(col) = x;
    }
  }
  if (!ok) throw std::invalid_argument("compliance contact: K is singular (does the model have a fixed support?)");
  // W is symmetric in exact arithmetic; make it so in floating point (the Newton matrix
  // is then symmetric positive definite, solved by Cholesky).
  W_ = 0.5 * (W_ + W_.transpose()).eval();
}

bool ComplianceContact::LoadCache(std::uint64_t key) {
  std::ifstream in(cache_file_, std::ios::binary);
  if (!in) return false;  // no file yet: not a rejection
  auto reject = [&](const char* why) {
    cache_rejected_ = why;
    return false;
  };
  char magic[8];
  std::uint64_t version = 0, file_key = 0, checksum = 0;
  std::int64_t w_rows = 0, g_rows = 0;
  in.read(magic, 8);
  in.read(reinterpret_cast<char*>(&version), sizeof version);
  in.read(reinterpret_cast<char*>(&file_key), sizeof file_key);
  in.read(reinterpret_cast<char*>(&w_rows), sizeof w_rows);
  in.read(reinterpret_cast<char*>(&g_rows), sizeof g_rows);
  if (!in || !std::equal(magic, magic + 8, kCacheMagic)) return reject("not a compliance cache file");
  if (version != kCacheVersion || file_key != key) return reject("built for another model or version");
  const std::int64_t c3 = 3 * std::int64_t(candidates_.size()), s3 = 3 * std::int64_t(sed_nodes_.size());
  if (w_rows != c3 || g_rows != s3) return reject("sizes do not match");
  Eigen::MatrixXd W(c3, c3), G(s3, c3);
  in.read(reinterpret_cast<char*>(W.data()), std::streamsize(W.size() * sizeof(double)));
  in.read(reinterpret_cast<char*>(G.data()), std::streamsize(G.size() * sizeof(double)));
  in.read(reinterpret_cast<char*>(&checksum), sizeof checksum);
  if (!in) return reject("truncated");
  if (in.peek() != std::char_traits<char>::eof()) return reject("trailing bytes");
  Fnv sum;
  sum.Bytes(W.data(), size_t(W.size()) * sizeof(double));
  sum.Bytes(G.data(), size_t(G.size()) * sizeof(double));
  if (sum.h != checksum || !W.allFinite() || !G.allFinite()) return reject("checksum mismatch (corrupt)");
  W_ = std::move(W);
  G_ = std::move(G);
  return true;
}

void ComplianceContact::SaveCache(std::uint64_t key) const {
  // Best effort: a cache that cannot be written only costs the next start its precompute.
  std::error_code ec;
  std::filesystem::create_directories(options_.cache_dir, ec);
  // Write beside, then rename: a reader never sees a half-written file.
  const std::string tmp = cache_file_ + ".tmp" + std::to_string(::getpid()) + "_" + std::to_string(std::uintptr_t(this));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return;
    const std::uint64_t version = kCacheVersion;
    const std::int64_t w_rows = W_.rows(), g_rows = G_.rows();
    Fnv sum;
    sum.Bytes(W_.data(), size_t(W_.size()) * sizeof(double));
    sum.Bytes(G_.data(), size_t(G_.size()) * sizeof(double));
    out.write(kCacheMagic, 8);
    out.write(reinterpret_cast<const char*>(&version), sizeof version);
    out.write(reinterpret_cast<const char*>(&key), sizeof key);
    out.write(reinterpret_cast<const char*>(&w_rows), sizeof w_rows);
    out.write(reinterpret_cast<const char*>(&g_rows), sizeof g_rows);
    out.write(reinterpret_cast<const char*>(W_.data()), std::streamsize(W_.size() * sizeof(double)));
    out.write(reinterpret_cast<const char*>(G_.data()), std::streamsize(G_.size() * sizeof(double)));
    out.write(reinterpret_cast<const char*>(&sum.h), sizeof sum.h);
    if (!out) {
      out.close();
      std::filesystem::remove(tmp, ec);
      return;
    }
  }
  std::filesystem::rename(tmp, cache_file_, ec);
  if (ec) std::filesystem::remove(tmp, ec);
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
  std::vector<char> next(anchored_.size(), 0);
  for (const int p : active_) {
    const Eigen::Vector3d x = rest_c_.col(p / no) + u_c_.segment<3>(3 * (p / no));
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

Eigen::VectorXd ComplianceContact::full_positions_m() const {
  if (F_.size() == 0) return {};
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(mesh_.rest_positions_m.data(), mesh_.rest_positions_m.size());
  for (int j : loaded_) AddSampleForce(j, f_c_.segment<3>(3 * j));  // F_ is over the nodes
  ApplyNodeForces(F_, x);
  return x;
}

void ComplianceContact::CandidateDisplacements(bool normal_forces_only) {
  u_c_.setZero();
  if (!normal_forces_only || num_objects_ <= 0) {
    AddWTimes(loaded_, [](int j) { return j; }, [&](int j) { return Eigen::Vector3d(f_c_.segment<3>(3 * j)); }, u_c_);
    return;
  }
  // A sample's force is the sum of its pairs' l_p n_p: where every such pair's row still
  // has its column of T (the last QP's, same direction), sum those columns instead of
  // reading three columns of W.
  const int no = num_objects_;
  std::vector<int>& from_w = from_w_;
  std::vector<int>& from_t = from_t_;
  from_w.clear();
  from_t.clear();
  for (int j : loaded_) {
    bool cached = true;
    for (int o = 0; o < no && cached; ++o) {
      const int p = j * no + o;
      if (lambda_N_[p] > 0) cached = CachedRowColumn(p, j, normal_.col(p)) >= 0;
    }
    if (!cached) {
      from_w.push_back(j);
      continue;
    }
    for (int o = 0; o < no; ++o)
      if (lambda_N_[j * no + o] > 0) from_t.push_back(j * no + o);
  }
  AddWTimes(from_w, [](int j) { return j; }, [&](int j) { return Eigen::Vector3d(f_c_.segment<3>(3 * j)); }, u_c_);
  AddColumnsOfT(from_t, [&](int p) { return t_slot_of_row_[size_t(p)]; }, [&](int p) { return lambda_N_[p]; }, u_c_);
}

int ComplianceContact::CachedRowColumn(int r, int sample, const Eigen::Vector3d& dir) const {
  if (size_t(r) >= t_slot_of_row_.size()) return -1;
  const int slot = t_slot_of_row_[size_t(r)];
  return slot >= 0 && t_has_column_[size_t(slot)] && t_sample_[size_t(slot)] == sample && t_dir_[size_t(slot)] == dir
             ? slot
             : -1;
}

int ComplianceContact::RowColumn(int r) {
  const int sample = row_node_[size_t(r)];
  const Eigen::Vector3d dir = row_dir_.col(r);
  int& slot = t_slot_of_row_[size_t(r)];
  if (slot < 0) {  // a new slot (grows only while a larger contact set appears)
    slot = int(t_sample_.size());
    t_sample_.push_back(-1);
    t_dir_.emplace_back();
    t_has_column_.push_back(0);
  }
  const size_t k = size_t(slot);
  if (t_sample_[k] != sample || t_dir_[k] != dir) {
    // A direction not seen before for this row (a curved object's normals turn every outer
    // iteration): no column; W serves this use directly, which is cheaper for one use.
    t_sample_[k] = sample;
    t_dir_[k] = dir;
    t_has_column_[k] = 0;
    return -1;
  }
  if (t_has_column_[k]) return slot;
  // The same sample and direction a second time: it is likely to hold (a plane), so the
  // column is worth its one pass over W.
  if (slot >= T_.cols()) T_.conservativeResize(W_.rows(), std::max<Eigen::Index>(std::max(32, slot + 1), 2 * T_.cols()));
  const Eigen::Index n = W_.rows();
  const double* w = W_.data() + 3 * Eigen::Index(sample) * n;
  SetThreeColumns(int(n), w, w + n, w + 2 * n, dir[0], dir[1], dir[2], T_.col(slot).data());
  t_has_column_[k] = 1;
  ++qp_counts_.columns_computed;
  return slot;
}

template <typename Items, typename SlotOf, typename CoefficientOf>
void ComplianceContact::AddColumnsOfT(const Items& items, const SlotOf& slot_of, const CoefficientOf& coefficient_of,
                                      Eigen::VectorXd& y) const {
  // Three columns per pass over y.
  const double* column[3];
  double coefficient[3];
  int k = 0;
  const int n = int(T_.rows());
  for (int item : items) {
    const double l = coefficient_of(item);
    if (l == 0) continue;
    column[k] = T_.col(slot_of(item)).data();
    coefficient[k] = l;
    if (++k == 3) {
      AddThreeColumns(n, column[0], column[1], column[2], coefficient[0], coefficient[1], coefficient[2], y.data());
      k = 0;
    }
  }
  for (; k > 0 && k < 3; ++k) column[k] = column[0], coefficient[k] = 0.0;
  if (k == 3) AddThreeColumns(n, column[0], column[1], column[2], coefficient[0], coefficient[1], coefficient[2], y.data());
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
  sed_current_ = false;
  result_.ok = result_.converged = result_.stale_warm_start = false;
  result_.iterations = 0;
  result_.error.clear();
  result_.contacts.clear();
  result_.spring_force_N.setZero();
  result_.tangential_force_N.setZero();
  result_.friction_force_N.setZero();
  if (!tangential_force_N.allFinite() || !std::isfinite(t_s)) {
    result_.error = "non-finite tangential force or time";
    return result_;
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
  const bool friction = options_.friction_anisotropy > 0;
  const double k_t = options_.friction_anisotropy * options_.stiffness_N_m;
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
      return result_;
    }
    base_pose_[size_t(o)] = objects[size_t(o)].trajectory.Pose(t_s);
  }
  // Force control moves every object by offset along its direction.
  double offset = control ? control->offset_m : 0.0;
  auto place_objects = [&] {
    for (int o = 0; o < no; ++o) {
      Eigen::Isometry3d pose = base_pose_[size_t(o)];
      if (control) pose.pretranslate(offset * control->direction_unit);
      pose_[size_t(o)] = pose;
      pose_inverse_[size_t(o)] = pose.inverse();
      pose_rotation_[size_t(o)] = pose.linear();
    }
  };
  place_objects();
  // Anderson history of the offset (its mapped value at the last iteration) and whether
  // the last move was cut to max_change_m (then the history says nothing).
  double previous_mapped_offset = offset;
  bool offset_capped = false;
  const double k = options_.stiffness_N_m;

  const bool exact = options_.exact_contact;
  bool converged_exact = false;
  bool have_previous = false;  // Anderson history valid (same contacts as last iteration)
  const bool warm_forces = control && HasContactForces();
  double warm_gap_m = std::numeric_limits<double>::infinity();  // least gap of a warm force, at the start
  bool previous_prediction_valid = false;  // previous_prediction_ = W (last QP's mapped forces)
  prediction_valid_ = false;
  for (int it = 0; it <= options_.max_iterations; ++it) {
    // The iteration's state: force vector l_p n_p of every pair that carries one (below).
    state_.clear();
    // 1. Displacements from the current forces: normal k*depth along each pair's normal,
    // plus the tangential load in proportion to each node's normal force.
    const double total = lambda_N_.sum();
    const Eigen::Vector3d tau = total > 0 ? Eigen::Vector3d(tangential_force_N / total) : Eigen::Vector3d::Zero();
    loaded_.clear();
    f_c_.setZero();
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
      if (node_lambda > 0 || rubbing) loaded_.push_back(j);
      if (node_lambda > 0) f_c_.segment<3>(3 * j) += node_lambda * tau;
    }
    // The QP's last prediction is exactly W f for these forces unless Anderson moved them
    // or the tangential share changed with them.
    if (prediction_valid_ && tangential_force_N.isZero(0.0))
      u_c_.swap(u_new_);
    else
      CandidateDisplacements(!friction && tangential_force_N.isZero(0.0));
    prediction_valid_ = false;

    // 2. Gaps and normals at the current positions; how far the forces are from k*depth.
    // Exact contact (no penetration, k -> infinity): forces only where the gap is closed,
    // gaps >= 0 everywhere; the mismatch is then the gap error times a stiffness scale.
    active_.clear();
    double largest = 0, mismatch = 0, gap_error = 0, turn = 0;
    double pushed_N = 0;  // force control: sum k depth n . direction at these positions
    for (int j = 0; j < c; ++j) {
      const Eigen::Vector3d x = rest_c_.col(j) + u_c_.segment<3>(3 * j);
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
          ResetWarmStart();
          return result_;
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
    result_.iterations = it;
    if (it == 0 && warm_forces && active_.empty() && warm_gap_m > control->max_change_m) {
      // Force control from forces that touch nothing where the objects start, every one
      // further than a move may go (the estimate moved since: the rig's pad-corner sphere,
      // whose warm contacts were on the finger's side, then walked 24 moves to the 5 mm
      // bound, 6.5 ms). Not a release (the skin just clear of the objects): the caller
      // starts from no contact.
      result_.stale_warm_start = true;
      break;
    }
    if (exact) {
      converged_exact = gap_error <= options_.relative_tolerance * kExactGapScale_m &&
                        turn <= options_.relative_tolerance * largest;
      if (converged_exact) {
        result_.converged = true;
        break;
      }
    } else if (control) {
      // The penalty law as a plain step, and the force: each active pair within the law's
      // tolerance bounds the force's error by #active times it.
      const double law = options_.relative_tolerance * largest;
      if (!active_.empty() && mismatch <= law && std::abs(pushed_N - control->target_N) <= double(active_.size()) * law) {
        result_.converged = true;
        break;
      }
    } else if (mismatch <= options_.relative_tolerance * largest || (active_.empty() && mismatch == 0)) {
      result_.converged = true;
      break;
    }
    if (it == options_.max_iterations) break;

    // 3. The contact problem with the gaps linearized about the current positions
    // (normals frozen, tangential part held) is a convex QP in the normal forces:
    //   min 1/2 l^T (N^T W N + I/k) l + q^T l,  l >= 0,
    // whose optimality conditions are exactly the penalty law l_p = k max(0, -gap_p).
    // Solved by a primal active-set method (Lawson-Hanson style): the objective falls at
    // every change of the active set, so it cannot cycle (a plain semismooth Newton on
    // max(0, .) does cycle here: N^T W N is not an M-matrix).
    if (!SolveLinearizedQp(no, tau, control)) {
      result_.error = control ? "force-controlled contact solve failed (no contact can carry the force, or NaN)"
                              : "contact solve produced NaN";
      ResetWarmStart();
      return result_;
    }
    // The QP freezes the normals; they turn as the skin slides over a curved object, and
    // that outer iteration converges only linearly (rate ~0.3 measured on B). Anderson
    // acceleration of depth 1 on the force vectors, while the contact set holds, makes
    // it superlinear in practice.
    // (Not with friction springs: their forces are not along the normals.)
    double accelerated_gamma = 0;  // set when Anderson moved the forces
    bool combined = false;         // ... and u_new_ is W times the moved forces
    if (!friction) {
      const bool qp_predicted = prediction_valid_ && tangential_force_N.isZero(0.0);  // u_new_ = W mapped
      mapped_.clear();
      for (Eigen::Index p = 0; p < lambda_N_.size(); ++p)
        if (lambda_N_[p] > 0) mapped_.push(int(p), lambda_N_[p] * normal_.col(p));
      // residual = mapped - state on the union of their pairs (both sorted).
      residual_.clear();
      MergePairs(mapped_, state_, [&](int p, const Eigen::Vector3d* m, const Eigen::Vector3d* s) {
        residual_.push(p, (m ? *m : Eigen::Vector3d::Zero()) - (s ? *s : Eigen::Vector3d::Zero()));
      });
      if (have_previous && mapped_.pairs == previous_mapped_.pairs) {
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
            const Eigen::Vector3d accelerated =
                mapped_.values[i] - gamma * (mapped_.values[i] - previous_mapped_.values[i]);
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
          combined = qp_predicted && previous_prediction_valid && moved == mapped_.pairs.size();
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
        previous_prediction_valid = qp_predicted;
        if (qp_predicted) previous_prediction_ = u_new_;
      }
      std::swap(previous_mapped_, mapped_);
      std::swap(previous_residual_, residual_);
      have_previous = true;
    }
    if (control) {
      // The QP's move, cut to max_change_m (a trust region against tunnelling), and
      // accelerated with the forces' coefficient while neither this nor the last was cut.
      const double change = std::clamp(qp_offset_change_m_, -control->max_change_m, control->max_change_m);
      const bool capped = change != qp_offset_change_m_;
      const double mapped_offset = offset + change;
      offset = mapped_offset;
      if (accelerated_gamma != 0 && !capped && !offset_capped)
        offset = mapped_offset - accelerated_gamma * (mapped_offset - previous_mapped_offset);
      previous_mapped_offset = mapped_offset;
      offset_capped = capped;
      if (capped) have_previous = false;
      if (!(offset >= -control->max_change_m && offset <= control->max_offset_m + control->max_change_m)) break;
      place_objects();
    }
  }
  if (control) {
    control->offset_m = offset;
    if (!(offset >= 0 && offset <= control->max_offset_m)) result_.converged = false;
  }

  // Report what the positions say (k * depth at the final gaps), as PenaltyContactForce.
  const double total = lambda_N_.sum();
  for (int p : active_) {
    const int i = p / no;
    const double spring = exact ? lambda_N_[p] : -k * phi_m_[p];
    result_.contacts.push_back(
        {sample_node_[size_t(i)], p % no, normal_.col(p), std::max(0.0, -phi_m_[p]), spring, spring, i});
    result_.spring_force_N += spring * normal_.col(p);
  }
  if (total > 0) result_.tangential_force_N = tangential_force_N;
  result_.friction_force_N.setZero();
  if (friction)
    for (Eigen::Index p = 0; p < friction_.cols(); ++p) result_.friction_force_N += friction_.col(p);

  result_.ok = true;
  if (compute_sed) ComputeSed();
  return result_;
}

void ComplianceContact::ComputeSed() {
  if (!result_.ok || sed_current_) return;
  const int c = int(candidates_.size());  // the node samples come first
  // SED from the displacements of the nodes it reads (G f: most of a step with few
  // contacts, so a root find over many steps asks for it only at its answer).
  u_s_.setZero();
  // Each loaded node through its kept column when its force kept its direction, else
  // through G's three columns.
  sed_kept_slots_.clear();
  sed_kept_coefficients_.clear();
  sed_triple_columns_.clear();
  auto take = [&](int column, const Eigen::Vector3d& f) {
    double coefficient = 0;
    const int slot = KeptSedColumn(column, f, &coefficient);
    if (slot >= 0) {
      sed_kept_slots_.push_back(slot);
      sed_kept_coefficients_.push_back(coefficient);
    } else {
      sed_forces_.col(Eigen::Index(sed_triple_columns_.size())) = f;
      sed_triple_columns_.push_back(column);
    }
  };
  if (options_.face_samples.empty()) {  // the candidates' own columns
    sed_forces_.resize(3, Eigen::Index(loaded_.size()));
    for (int j : loaded_) take(j, f_c_.segment<3>(3 * j));
  } else {  // G_ is over the nodes
    for (int j : loaded_) AddSampleForce(j, f_c_.segment<3>(3 * j));
    sed_forces_.resize(3, Eigen::Index(forced_nodes_.size()));
    TakeNodeForces(take);
  }
  qp_counts_.sed_kept_reads += sed_kept_slots_.size();
  const double entries =
      double(G_single_.rows()) * (3.0 * double(sed_triple_columns_.size()) + double(sed_kept_slots_.size()));
  const int product_team = entries >= options_.sed_parallel_min_entries ? omp_get_max_threads() : 1;
  AddColumnsByRowBlocks(G_single_, sed_triple_columns_, sed_forces_, product_team, u_s_);
  AddKeptColumnsByRowBlocks(sed_kept_, sed_kept_slots_, sed_kept_coefficients_, product_team, u_s_);
  for (size_t a = 0; a < sed_nodes_.size(); ++a) {
    const int v = sed_nodes_[a];
    x_.segment<3>(3 * v) = mesh_.rest_positions_m.col(v) + u_s_.segment<3>(3 * Eigen::Index(a));
  }
  for (int j = 0; j < c; ++j) x_.segment<3>(3 * candidates_[size_t(j)]) = rest_c_.col(j) + u_c_.segment<3>(3 * j);
  // Linear SED straight from the displacement gradient (same value as ElementSed with
  // R = I, a third of its work: this is most of a step with few contacts).
  const int count = int(sed_mu_Pa_.size());
  element_sed_.resize(count);
  const int team = count >= options_.sed_parallel_min_elements ? omp_get_max_threads() : 1;
  ForEachRowBlock(count, team, [&](Eigen::Index begin, Eigen::Index end) {
    LinearElementSeds(int(begin), int(end), count, sed_offset_.data(), sed_gradient_.data(), sed_mu_Pa_.data(),
                      sed_lambda_Pa_.data(), u_s_.data(), element_sed_.data());
  });
  sed_->AverageToVertices(element_sed_, result_.sed_Pa);
  sed_current_ = true;
}

int ComplianceContact::KeptSedColumn(int node, const Eigen::Vector3d& f, double* coefficient) {
  const Eigen::Index rows = G_single_.rows();
  const double size = f.norm();
  if (sed_kept_budget_ <= 0 || !(size > 0)) return -1;
  SedDirection& d = sed_direction_[size_t(node)];
  const double along = f.dot(d.dir);
  if (!((f - along * d.dir).norm() <= 1e-12 * size)) {  // turned (or first seen): remember where
    if (d.slot >= 0) sed_kept_free_.push_back(d.slot);
    d.slot = -1;
    d.dir = f / size;
    return -1;
  }
  if (d.slot < 0) {  // the second time along d: keep G(:, node) d
    if (!sed_kept_free_.empty()) {
      d.slot = sed_kept_free_.back();
      sed_kept_free_.pop_back();
    } else if (sed_kept_.cols() < sed_kept_budget_) {
      // Grow in steps (a plane's patch arrives in a step or two), keeping what is there.
      const Eigen::Index cols = sed_kept_.cols();
      const Eigen::Index grown = std::min<Eigen::Index>(sed_kept_budget_, std::max<Eigen::Index>(32, 2 * cols));
      sed_kept_.conservativeResize(rows, grown);
      for (Eigen::Index slot = grown - 1; slot > cols; --slot) sed_kept_free_.push_back(int(slot));
      d.slot = int(cols);
    } else {
      return -1;  // out of the budget: three columns
    }
    // From G's float columns as the three-column product reads them, summed in double and
    // stored in single precision as G is (ComplianceContact.KeptSedColumnsGiveTheThreeColumnSed:
    // the same SED to 1e-6).
    const float* g = G_single_.data() + 3 * Eigen::Index(node) * rows;
    SetThreeColumns(int(rows), g, g + rows, g + 2 * rows, d.dir[0], d.dir[1], d.dir[2], sed_kept_.col(d.slot).data());
    ++qp_counts_.sed_columns_kept;
  }
  *coefficient = along;
  return d.slot;
}

double ComplianceContact::QpEntry(int r, int slot_r, int q, int slot_q) const {
  const int i_r = row_node_[size_t(r)], i_q = row_node_[size_t(q)];
  // From q's column of T, else r's (J is symmetric), else W's block.
  if (slot_q >= 0) return row_dir_.col(r).dot(Eigen::Map<const Eigen::Vector3d>(T_.col(slot_q).data() + 3 * i_r));
  if (slot_r >= 0) return row_dir_.col(q).dot(Eigen::Map<const Eigen::Vector3d>(T_.col(slot_r).data() + 3 * i_q));
  return row_dir_.col(r).dot(W_.block<3, 3>(3 * i_r, 3 * i_q) * row_dir_.col(q));
}

bool ComplianceContact::UpdateFactor(int rows) {
  const int m = int(passive_.size());
  std::vector<int>& slot = passive_slot_;
  // Which of the factor's rows are still passive, with the sample, direction and
  // compliance they were factored with (a plane's rows, step after step).
  std::vector<int>& slot_of = row_slot_;  // passive row -> its slot + 2 (0: not passive)
  slot_of.assign(size_t(rows), 0);
  for (int a = 0; a < m; ++a) slot_of[size_t(passive_[size_t(a)])] = slot[size_t(a)] + 2;
  const int f = int(factor_rows_.size());
  int kept = 0;
  std::vector<char>& keep = factor_keep_;
  keep.assign(size_t(f), 0);
  for (int a = 0; a < f; ++a) {
    const int r = factor_rows_[size_t(a)];
    const FactorRow& key = factor_keys_[size_t(a)];
    if (r < rows && slot_of[size_t(r)] && key.sample == row_node_[size_t(r)] && key.dir == row_dir_.col(r) &&
        key.compliance == row_compliance_[r]) {
      keep[size_t(a)] = 1;
      slot_of[size_t(r)] = -slot_of[size_t(r)];  // marked: in the factor
      ++kept;
    }
  }
  const int changes = (f - kept) + (m - kept);
  // Rank-one changes cost O(m^2) each, a new factor O(m^3 / 3): update while few change.
  const bool update = m > 0 && kept > 0 && changes <= std::max(4, m / 8);
  if (update) {
    if (changes == 0) ++qp_counts_.factor_reuses;
    for (int a = f - 1; a >= 0; --a) {
      if (keep[size_t(a)]) continue;
      factor_.Remove(a);
      factor_rows_.erase(factor_rows_.begin() + a);
      factor_keys_.erase(factor_keys_.begin() + a);
      ++qp_counts_.factor_updates;
    }
    std::vector<double>& column = factor_column_;
    bool appended = true;
    for (int b = 0; b < m && appended; ++b) {
      const int q = passive_[size_t(b)];
      if (slot_of[size_t(q)] < 0) continue;  // in the factor already
      column.clear();
      for (int r : factor_rows_) column.push_back(QpEntry(r, std::abs(slot_of[size_t(r)]) - 2, q, slot[size_t(b)]));
      column.push_back(QpEntry(q, slot[size_t(b)], q, slot[size_t(b)]) + row_compliance_[q]);
      appended = factor_.Append(column.data());
      if (appended) {
        factor_rows_.push_back(q);
        factor_keys_.push_back({row_node_[size_t(q)], row_dir_.col(q), row_compliance_[q]});
        slot_of[size_t(q)] = -slot_of[size_t(q)];
        ++qp_counts_.factor_updates;
      }
    }
    if (appended) {
      // The QP goes on in the factor's row order.
      for (int a = 0; a < m; ++a) {
        passive_[size_t(a)] = factor_rows_[size_t(a)];
        slot[size_t(a)] = std::abs(slot_of[size_t(factor_rows_[size_t(a)])]) - 2;
      }
      return true;
    }
    // A nearly dependent row: factor anew.
  }
  // J = D^T W_PP D in the passive order, then its Cholesky factor.
  J_.resize(m, m);
  for (int b = 0; b < m; ++b) {
    const int q = passive_[size_t(b)];
    for (int a = b; a < m; ++a) J_(a, b) = QpEntry(passive_[size_t(a)], slot[size_t(a)], q, slot[size_t(b)]);
    J_(b, b) += row_compliance_[q];
  }
  factor_rows_.clear();
  factor_keys_.clear();
  if (m == 0) {
    factor_.Clear();
    return true;
  }
  ++qp_counts_.factorizations;
  if (!factor_.Factor(m, J_.data(), m)) return false;
  factor_rows_ = passive_;
  for (int q : passive_) factor_keys_.push_back({row_node_[size_t(q)], row_dir_.col(q), row_compliance_[q]});
  return true;
}

bool ComplianceContact::SolveLinearizedQp(int no, const Eigen::Vector3d& tau, const ForceControl* control) {
  const double k = options_.stiffness_N_m;
  const bool friction = options_.friction_anisotropy > 0;
  const double k_t = options_.friction_anisotropy * k;
  // Exact contact: no penalty compliance; a whisper of it keeps the Newton matrix definite
  // when two contacts act on one node along dependent normals.
  const double inverse_k = options_.exact_contact ? (W_.size() ? kExactContactRegularization * W_.diagonal().maxCoeff() : 0.0) : 1.0 / k;
  const Eigen::Index pairs = lambda_N_.size();
  const int c = num_samples();

  // Forces held fixed in this QP: the tangential load (shares of the current normal
  // forces). u_t_ = W held.
  held_.setZero(3 * c);
  for (Eigen::Index p = 0; p < pairs; ++p)
    if (lambda_N_[p] > 0) held_.segment<3>(3 * (int(p) / no)) += lambda_N_[p] * tau;
  // Only samples with a normal force hold a share, and loaded_ lists them (this iteration's
  // forces, in order).
  u_t_.setZero(3 * c);
  AddWTimes(loaded_, [](int j) { return j; }, [&](int j) { return Eigen::Vector3d(held_.segment<3>(3 * j)); }, u_t_);

  // Rows: force lambda_r along dir_r at node_r with "gap" g_r (linearized about the
  // current positions) and compliance c_r: lambda_r = -g_r(new) / c_r. Normal rows are
  // bounded (lambda >= 0: the penalty never pulls); friction rows (two tangent directions
  // of an anchored contact, gap = offset from the anchor) are free.
  bounded_rows_ = int(pairs);
  int rows = int(pairs);
  if (friction)
    for (Eigen::Index p = 0; p < pairs; ++p) rows += sticking_[size_t(p)] ? 2 : 0;
  row_node_.resize(size_t(rows));
  row_dir_.resize(3, rows);
  row_gap_.resize(rows);
  row_lambda_.resize(rows);
  row_compliance_.resize(rows);
  // Block copies, and the node of pair p = j * no + o without an integer division per pair
  // (570 of them per QP with face contact).
  for (int j = 0, p = 0; p < int(pairs); ++j)
    for (int o = 0; o < no; ++o) row_node_[size_t(p++)] = j;
  row_dir_.leftCols(pairs) = normal_;
  row_gap_.head(pairs) = phi_m_;
  row_lambda_.head(pairs) = lambda_N_;
  row_compliance_.head(pairs).setConstant(inverse_k);
  if (friction) {
    int r = int(pairs);
    for (Eigen::Index p = 0; p < pairs; ++p) {
      if (!sticking_[size_t(p)]) continue;
      const int j = int(p) / no;
      const Eigen::Vector3d n = normal_.col(p);
      const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
      const Eigen::Vector3d offset = rest_c_.col(j) + u_c_.segment<3>(3 * j) - anchor_world_.col(p);
      for (const Eigen::Vector3d& t : {t1, t2}) {
        row_node_[size_t(r)] = j;
        row_dir_.col(r) = t;
        row_gap_[r] = t.dot(offset);
        row_lambda_[r] = t.dot(friction_.col(p));
        row_compliance_[r] = 1.0 / k_t;
        ++r;
      }
    }
  }

  ++qp_counts_.qps;
  // Rows keep their columns of T from earlier QPs where their sample and direction have not
  // changed (a plane's rows, step after step); the slot map is per row index.
  t_slot_of_row_.resize(size_t(rows), -1);

  // Force control: the rows' forces must push target_N along the direction; the objects'
  // move delta (the multiplier of that constraint) closes each gap by delta * push_r. The
  // active-set iterates all carry the target (convex combinations of points that do), so
  // start from one that does: the warm forces scaled to it, else the row that closes
  // first as the objects move.
  double delta = 0;
  if (control) {
    row_push_.setZero(rows);
    double carried = 0;
    for (int r = 0; r < bounded_rows_; ++r) {
      row_push_[r] = control->direction_unit.dot(row_dir_.col(r));
      if (row_lambda_[r] > 0) carried += row_push_[r] * row_lambda_[r];
    }
    if (carried > 0) {
      for (int r = 0; r < bounded_rows_; ++r) row_lambda_[r] *= control->target_N / carried;
    } else {
      int first = -1;
      double closes_at = std::numeric_limits<double>::infinity();
      for (int r = 0; r < bounded_rows_; ++r) {
        row_lambda_[r] = 0;
        if (row_push_[r] > kMinPush && row_gap_[r] / row_push_[r] < closes_at) closes_at = row_gap_[r] / row_push_[r], first = r;
      }
      if (first < 0) return false;
      row_lambda_[first] = control->target_N / row_push_[first];
    }
  }
  // Predicted displacements for the passive rows' forces l: u_t + sum_r l_r W dir_r, from
  // T where a row has its column (passive_slot_, as the QP matrix was built), else from W.
  auto predicted_displacements = [&](const Eigen::VectorXd& l) {
    u_new_ = u_t_;
    with_column_.clear();
    without_column_.clear();
    for (size_t a = 0; a < passive_.size(); ++a)
      (passive_slot_[a] >= 0 ? with_column_ : without_column_).push_back(int(a));
    AddColumnsOfT(with_column_, [&](int a) { return passive_slot_[size_t(a)]; },
                  [&](int a) { return l[passive_[size_t(a)]]; }, u_new_);
    AddWTimes(without_column_, [&](int a) { return row_node_[size_t(passive_[size_t(a)])]; },
              [&](int a) {
                const int r = passive_[size_t(a)];
                return Eigen::Vector3d(l[r] * row_dir_.col(r));
              },
              u_new_);
  };
  passive_.clear();
  for (int r = 0; r < rows; ++r)
    if (r >= bounded_rows_ || row_lambda_[r] > 0) passive_.push_back(r);
  // Work lists are members: no allocation once they have grown (the step is real time).
  std::vector<int>& before_add = before_add_;
  before_add.clear();
  int most_violated = -1;
  bool batch_added = false;
  largest_ = 0;
  bool solved = false;
  for (int inner = 0; inner < 4 * rows + 10; ++inner) {
    // Unconstrained minimizer on the passive set.
    const int m = int(passive_.size());
    rhs_.resize(m);
    std::vector<int>& slot = passive_slot_;
    slot.resize(size_t(m));
    for (int a = 0; a < m; ++a) slot[size_t(a)] = RowColumn(passive_[size_t(a)]);
    if (!UpdateFactor(rows)) return false;
    for (int b = 0; b < m; ++b) {
      const int q = passive_[size_t(b)], i = row_node_[size_t(q)];
      rhs_[b] = -row_gap_[q] + row_dir_.col(q).dot(u_c_.segment<3>(3 * i) - u_t_.segment<3>(3 * i));
    }
    if (m) {
      z_ = rhs_;
      factor_.Solve(z_.data());
      if (control) {  // J l = rhs + delta push, push . l = target
        push_passive_.resize(m);
        for (int a = 0; a < m; ++a) push_passive_[a] = row_push_[passive_[size_t(a)]];
        y_ = push_passive_;
        factor_.Solve(y_.data());
        const double denominator = push_passive_.dot(y_);
        if (!(denominator > 0)) return false;
        delta = (control->target_N - push_passive_.dot(z_)) / denominator;
        z_ += delta * y_;
      }
    } else {
      if (control) return false;
      z_.resize(0);
    }
    if (!z_.allFinite()) return false;
    // Infeasible: step from l toward z until the first bounded force reaches zero, drop it.
    double alpha = 1;
    for (int a = 0; a < m; ++a) {
      const int r = passive_[size_t(a)];
      if (r < bounded_rows_ && z_[a] <= 0) alpha = std::min(alpha, row_lambda_[r] / (row_lambda_[r] - z_[a]));
    }
    if (alpha < 1) {
      if (alpha <= 0 && batch_added) {
        // A row added in the last batch wants a negative force at once: add only the
        // most violated one instead (Lawson-Hanson's rule, which always makes progress).
        passive_ = before_add;
        passive_.push_back(most_violated);
        batch_added = false;
        continue;
      }
      std::vector<int>& kept = kept_;
      kept.clear();
      for (int a = 0; a < m; ++a) {
        const int r = passive_[size_t(a)];
        row_lambda_[r] += alpha * (z_[a] - row_lambda_[r]);
        if (r >= bounded_rows_) {
          kept.push_back(r);
          continue;
        }
        if (z_[a] <= 0 && row_lambda_[r] <= 1e-14 * (1 + std::abs(z_[a]))) row_lambda_[r] = 0;
        if (row_lambda_[r] > 0) kept.push_back(r);
      }
      passive_.swap(kept);
      batch_added = false;
      continue;
    }
    for (int a = 0; a < m; ++a) row_lambda_[passive_[size_t(a)]] = z_[a];
    // Optimal on the passive set: any other normal row predicted to penetrate joins it.
    predicted_displacements(row_lambda_);
    for (int a = 0; a < m; ++a)
      if (passive_[size_t(a)] < bounded_rows_) largest_ = std::max(largest_, z_[a]);
    const double gap_tolerance = options_.exact_contact
                                     ? 1e-3 * options_.relative_tolerance * kExactGapScale_m
                                     : 1e-3 * options_.relative_tolerance * std::max(largest_, kMinForceScale_N) / k;
    before_add = passive_;
    most_violated = -1;
    double worst = -gap_tolerance;
    std::vector<char>& in_passive = in_passive_;
    in_passive.assign(size_t(rows), 0);
    for (int r : passive_) in_passive[size_t(r)] = 1;
    for (int r = 0; r < bounded_rows_; ++r) {
      if (in_passive[size_t(r)]) continue;
      const int i = row_node_[size_t(r)];
      double gap = row_gap_[r] + row_dir_.col(r).dot(u_new_.segment<3>(3 * i) - u_c_.segment<3>(3 * i));
      if (control) gap -= delta * row_push_[r];
      if (gap < -gap_tolerance) passive_.push_back(r);
      if (gap < worst) worst = gap, most_violated = r;
    }
    if (most_violated < 0) {
      solved = true;
      break;
    }
    batch_added = passive_.size() > before_add.size() + 1;
  }
  // Back to pairs: normal forces, and the friction of spring pairs from their rows.
  for (Eigen::Index p = 0; p < pairs; ++p) lambda_N_[p] = std::max(0.0, row_lambda_[p]);
  if (friction) {
    friction_.setZero();
    int r = bounded_rows_;
    for (Eigen::Index p = 0; p < pairs; ++p) {
      if (!sticking_[size_t(p)]) continue;
      friction_.col(p) = row_lambda_[r] * row_dir_.col(r) + row_lambda_[r + 1] * row_dir_.col(r + 1);
      r += 2;
    }
  }
  // u_new_ = W f for exactly these forces when the set settled (reused as the next
  // iteration's displacements).
  prediction_valid_ = solved;
  qp_offset_change_m_ = delta;
  return true;  // not solved: out of inner iterations, the outer loop reports non-convergence
}

}  // namespace sedbridge::fem
