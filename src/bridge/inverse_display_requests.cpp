#include "bridge/inverse_display_requests.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/thread_cpu_time.h"

namespace sedbridge::bridge {
namespace {

// Two vertex positions agree within this [mm]: the same mesh read twice gives equal numbers.
constexpr double kSameVertex_mm = 1e-6;

// The leader's Merkel layer must be the bridge's: same vertices, same order (both are the
// model's merkel_nodes; fe.merkel_region: display would have filtered the bridge's).
void CheckSameLayer(const model::FingertipModel& m, const Eigen::Matrix3Xd& bridge_pad_mm, const std::string& name) {
  const size_t n = m.merkel_nodes.size();
  const std::string what = "display.rendering: inverse: the leader's Merkel layer (model " + name + ", " +
                           std::to_string(n) + " vertices) ";
  if (size_t(bridge_pad_mm.cols()) != n)
    throw std::invalid_argument(what + "is not the bridge FE step's (" + std::to_string(bridge_pad_mm.cols()) +
                                " vertices): the inverse renderer needs the whole layer (fe.merkel_region: layer)");
  for (size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d p = m.pad_frame.ToPad(m.soft.rest_positions_m.col(m.merkel_nodes[k])) * 1e3;
    if ((p - bridge_pad_mm.col(Eigen::Index(k))).norm() > kSameVertex_mm)
      throw std::invalid_argument(what + "differs from the bridge FE step's at vertex " + std::to_string(k));
  }
}

}  // namespace

std::shared_ptr<InverseRenderingPrecompute> InverseRenderingCache::Get(
    const std::string& key, const std::function<std::shared_ptr<InverseRenderingPrecompute>()>& build) {
  auto it = by_key_.find(key);
  if (it != by_key_.end()) {
    ++shared_;
    return it->second;
  }
  std::shared_ptr<InverseRenderingPrecompute> made = build();
  ++built_;
  by_key_.emplace(key, made);
  return made;
}

InverseDisplayRequests::InverseDisplayRequests(const BridgeConfig& config, const display::DisplayProfile& profile,
                                               const Eigen::Matrix3Xd& merkel_rest_pad_mm,
                                               const std::function<void(const std::string&)>& progress,
                                               InverseRenderingCache* cache) {
  const auto start = std::chrono::steady_clock::now();
  auto build = [&] {
    auto p = std::make_shared<InverseRenderingPrecompute>();
    p->model = model::LoadFingertipModel(config.model);
    CheckSameLayer(p->model, merkel_rest_pad_mm, config.model);
    if (progress)
      progress("display rendering: inverse FE precompute: leader contact model of " + config.model + " (cache " +
               (config.compliance_cache_dir.empty() ? std::string("none") : config.compliance_cache_dir) + "), then " +
               std::to_string(profile.size() + 1) + " contact solves (n + 1, n = " + std::to_string(profile.size()) +
               " actuators of " + profile.name + ") ...");
    render::DisplayRenderingOptions options;
    options.cache_dir = config.compliance_cache_dir;
    options.renderer.max_iterations = config.display_render_iterations;
    options.renderer.max_evaluations = config.display_render_evaluations;
    options.fit_reduction = config.display_fit_reduction;
    p->rendering = std::make_unique<render::DisplayRendering>(p->model, profile, options);
    p->precompute_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return p;
  };
  if (cache) {
    const std::string key = config.model + "|" + profile.name + "|" + config.compliance_cache_dir + "|" +
                            std::to_string(config.display_render_iterations) + "|" +
                            std::to_string(config.display_render_evaluations) + "|" +
                            std::to_string(config.display_fit_reduction);
    precompute_ = cache->Get(key, build);
    CheckSameLayer(precompute_->model, merkel_rest_pad_mm, config.model);  // this finger's step against it
  } else {
    precompute_ = build();
  }
  // A copy of the never-run shared renderer: the same start as a renderer of one's own.
  renderer_ = std::make_unique<render::InverseRenderer>(precompute_->rendering->renderer());
  target_Pa_.resize(merkel_rest_pad_mm.cols());
  precompute_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void InverseDisplayRequests::Request(const display::SedField& field, std::vector<double>* requested) {
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start_ms = ThreadCpuTime_ms();
  requested->assign(size_t(num_actuators()), std::numeric_limits<double>::quiet_NaN());
  // Another layer than the one the influence was built on: fault, never a guess.
  if (field.sed_Pa.size() != size_t(target_Pa_.size())) return;
  for (Eigen::Index v = 0; v < target_Pa_.size(); ++v) target_Pa_[v] = std::max(field.sed_Pa[size_t(v)], 0.0);
  const Eigen::VectorXd& u = renderer_->Render(target_Pa_);
  if (renderer_->last().fault) return;
  not_converged_ += renderer_->last().converged ? 0 : 1;
  const size_t evaluations = size_t(std::max(0, renderer_->last().evaluations));
  if (evaluations >= evaluations_histogram_.size()) evaluations_histogram_.resize(evaluations + 1, 0);
  ++evaluations_histogram_[evaluations];
  std::copy(u.data(), u.data() + u.size(), requested->begin());
  render_times_.AddMs(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  render_cpu_times_.AddMs(ThreadCpuTime_ms() - cpu_start_ms);
  render_times_.ResetWindow();  // only the run's summary is read
  render_cpu_times_.ResetWindow();
}

InverseDisplayRequests::EvaluationCounts InverseDisplayRequests::evaluation_counts() const {
  EvaluationCounts c;
  for (int64_t n : evaluations_histogram_) c.renders += n;
  if (c.renders == 0) return c;
  // Nearest rank, as LatencyStats's percentiles.
  auto rank = [&](double q) {
    const int64_t k = std::max<int64_t>(1, int64_t(std::ceil(q * double(c.renders))));
    int64_t seen = 0;
    for (size_t e = 0; e < evaluations_histogram_.size(); ++e)
      if ((seen += evaluations_histogram_[e]) >= k) return int(e);
    return int(evaluations_histogram_.size()) - 1;
  };
  c.median = rank(0.5);
  c.p99 = rank(0.99);
  c.max = rank(1.0);
  return c;
}

display::CommandRequestSource InverseDisplayRequests::Source(std::shared_ptr<InverseDisplayRequests> self) {
  return [self = std::move(self)](const display::SedField& field, std::vector<double>* requested) {
    self->Request(field, requested);
  };
}

void InverseDisplayRequests::PredictedSed(Eigen::VectorXd* added_sed_Pa, std::vector<double>* commands) const {
  const render::InverseRenderer& renderer = *renderer_;
  renderer.AddedSed(*added_sed_Pa);
  const Eigen::VectorXd& u = renderer.commands();
  commands->assign(u.data(), u.data() + u.size());
}

bool InverseDisplayRequests::Deliver(const std::vector<double>& commands, Eigen::VectorXd* delivered_sed_Pa) {
  const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(commands.data(), Eigen::Index(commands.size()));
  std::lock_guard<std::mutex> lock(precompute_->deliver_mutex);
  return precompute_->rendering->Deliver(u, *delivered_sed_Pa);
}

}  // namespace sedbridge::bridge
