#include "fem/compliance_operator.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>
#include <utility>

#include "fem/elastic_tet_force.h"
#include "fem/stiffness_inverse.h"

namespace sedbridge::fem {

namespace {

// Bump when the cache layout or the meaning of W/G changes: old files then stop matching.
constexpr std::uint64_t kCacheVersion = 1;
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

// The key covers everything W and G depend on: K (mesh, materials, supports), which nodes
// are candidates and which the SED reads.
std::uint64_t CacheKey(const SystemMatrix& K, const std::vector<int>& candidates, const std::vector<int>& sed_nodes) {
  Fnv key;
  key.Pod(kCacheVersion);
  key.Pod(std::int64_t(K.num_nodes()));
  const auto& csr = K.csr();
  key.Bytes(csr.outerIndexPtr(), size_t(csr.outerSize() + 1) * sizeof(int));
  key.Bytes(csr.innerIndexPtr(), size_t(csr.nonZeros()) * sizeof(int));
  key.Bytes(csr.valuePtr(), size_t(csr.nonZeros()) * sizeof(double));
  key.Vector(candidates);
  key.Vector(sed_nodes);
  return key.h;
}

}  // namespace

const ElasticTetForce& LinearElasticTermOf(const std::vector<std::unique_ptr<ForceTerm>>& terms) {
  const ElasticTetForce* elastic = nullptr;
  for (const auto& t : terms) {
    if (!t->JacobianIsConstant())
      throw std::invalid_argument("compliance contact: term '" + t->name() + "' has a non-constant Jacobian");
    if (!elastic) elastic = dynamic_cast<const ElasticTetForce*>(t.get());
  }
  if (!elastic || elastic->formulation() != ElasticFormulation::kLinear)
    throw std::invalid_argument("compliance contact needs a linear elastic term (the compliance is K^-1 at rest)");
  return *elastic;
}

void AssembleRestStiffness(const TetMesh& mesh, const std::vector<std::unique_ptr<ForceTerm>>& terms, SystemMatrix& K) {
  const int n = mesh.num_nodes();
  std::vector<std::pair<int, int>> pairs;
  for (const auto& t : terms) t->AppendCoupledNodes(pairs);
  K.Build(n, pairs);
  for (const auto& t : terms) t->BindMatrix(K);
  K.SetZero();
  Eigen::VectorXd x(3 * n);
  for (int i = 0; i < n; ++i) x.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(3 * n);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * n);
  JacobianSink sink{&K, 1.0, 0.0};
  const SystemState rest{x, v, 0.0, false};
  for (const auto& t : terms) t->AddForce(rest, f, &sink);
}

ComplianceOperator::ComplianceOperator(const TetMesh& mesh, const SystemMatrix& K, std::vector<int> candidate_nodes,
                                       std::vector<int> sed_nodes, ComplianceOperatorOptions options)
    : mesh_(mesh), candidates_(std::move(candidate_nodes)), sed_nodes_(std::move(sed_nodes)), options_(std::move(options)) {
  const auto t0 = std::chrono::steady_clock::now();
  CheckInputs(mesh.num_nodes());
  const std::uint64_t key = CacheKey(K, candidates_, sed_nodes_);
  if (!options_.cache_dir.empty()) {
    char name[64];
    std::snprintf(name, sizeof name, "compliance_%016llx.bin", static_cast<unsigned long long>(key));
    cache_file_ = (std::filesystem::path(options_.cache_dir) / name).string();
  }
  loaded_from_cache_ = !cache_file_.empty() && !options_.full_field && LoadCache(key);
  if (!loaded_from_cache_) {
    Precompute(K);
    if (!cache_file_.empty()) SaveCache(key);
  }
  const int c = int(candidates_.size());
  rest_samples_m_.resize(3, c);
  for (int j = 0; j < c; ++j) rest_samples_m_.col(j) = mesh.rest_positions_m.col(candidates_[size_t(j)]);
  sample_node_ = candidates_;
  if (!options_.face_samples.empty()) AddFaceSamples();
  precompute_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void ComplianceOperator::CheckInputs(int num_nodes) const {
  const std::set<int> unique(candidates_.begin(), candidates_.end());
  if (unique.size() != candidates_.size() || (!unique.empty() && (*unique.begin() < 0 || *unique.rbegin() >= num_nodes)))
    throw std::invalid_argument("compliance contact: candidate nodes must be unique mesh nodes");
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
}

void ComplianceOperator::AddFaceSamples() {
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
  rest_samples_m_.conservativeResize(3, S);
  sample_node_.resize(size_t(S));
  for (int k = 0; k < e; ++k) {
    const ContactSample& sample = options_.face_samples[size_t(k)];
    rest_samples_m_.col(c + k).setZero();
    for (int a = 0; a < 3; ++a)
      rest_samples_m_.col(c + k) += sample.weight[size_t(a)] * rest_samples_m_.col(sample.candidate[size_t(a)]);
    sample_node_[size_t(c + k)] = candidates_[size_t(sample.candidate[0])];
  }
}

NodeForceScratch ComplianceOperator::MakeScratch() const {
  const int c = int(candidates_.size());
  NodeForceScratch s;
  s.node_force = s.node_u = Eigen::VectorXd::Zero(3 * c);
  s.node_forced.assign(size_t(c), 0);
  return s;
}

void ComplianceOperator::AddSampleForce(int j, const Eigen::Vector3d& f, NodeForceScratch& scratch) const {
  const int c = int(candidates_.size());
  auto add = [&](int node, const Eigen::Vector3d& g) {
    if (!scratch.node_forced[size_t(node)]) {
      scratch.node_forced[size_t(node)] = 1;
      scratch.forced_nodes.push_back(node);
    }
    scratch.node_force.segment<3>(3 * node) += g;
  };
  if (j < c) {
    add(j, f);
    return;
  }
  const ContactSample& sample = options_.face_samples[size_t(j - c)];
  for (int a = 0; a < 3; ++a) add(sample.candidate[size_t(a)], sample.weight[size_t(a)] * f);
}

void ComplianceOperator::AddToSamples(const Eigen::VectorXd& u_nodes, Eigen::VectorXd& u_samples) const {
  const int c = int(candidates_.size());
  u_samples.head(3 * c) += u_nodes;
  for (size_t k = 0; k < options_.face_samples.size(); ++k) {
    const ContactSample& sample = options_.face_samples[k];
    auto u = u_samples.segment<3>(3 * (c + Eigen::Index(k)));
    for (int a = 0; a < 3; ++a) u += sample.weight[size_t(a)] * u_nodes.segment<3>(3 * sample.candidate[size_t(a)]);
  }
}

Eigen::VectorXd ComplianceOperator::FullPositions(const std::vector<int>& loaded, const Eigen::VectorXd& f_samples_N) const {
  if (F_.size() == 0) return {};
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(mesh_.rest_positions_m.data(), mesh_.rest_positions_m.size());
  NodeForceScratch scratch = MakeScratch();
  for (int j : loaded) AddSampleForce(j, f_samples_N.segment<3>(3 * j), scratch);  // F_ is over the nodes
  ApplyNodeForces(F_, x, scratch);
  return x;
}

void ComplianceOperator::Precompute(const SystemMatrix& K) {
  const int c = int(candidates_.size());
  const int s = int(sed_nodes_.size());
  W_.resize(3 * c, 3 * c);
  G_.resize(3 * s, 3 * c);
  if (options_.full_field) F_.resize(3 * K.num_nodes(), 3 * c);
  // One back-substitution per candidate dof (column of K^-1 H^T).
  std::vector<int> dofs(size_t(3 * c));
  for (int col = 0; col < 3 * c; ++col) dofs[size_t(col)] = 3 * candidates_[size_t(col / 3)] + col % 3;
  const bool ok = SolveForUnitDofs(
      K, dofs,
      [&](int col, const Eigen::VectorXd& x) {
        for (int j = 0; j < c; ++j) W_.block<3, 1>(3 * j, col) = x.segment<3>(3 * candidates_[size_t(j)]);
        for (int j = 0; j < s; ++j) G_.block<3, 1>(3 * j, col) = x.segment<3>(3 * sed_nodes_[size_t(j)]);
        if (options_.full_field) F_.col(col) = x;
      },
      options_.precompute_threads);
  if (!ok) throw std::invalid_argument("compliance contact: K is singular (does the model have a fixed support?)");
  // W is symmetric in exact arithmetic; make it so in floating point (the contact QP's
  // matrix is then symmetric positive definite, solved by Cholesky).
  W_ = 0.5 * (W_ + W_.transpose()).eval();
}

bool ComplianceOperator::LoadCache(std::uint64_t key) {
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

void ComplianceOperator::SaveCache(std::uint64_t key) const {
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

}  // namespace sedbridge::fem
