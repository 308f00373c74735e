#pragma once
// The display's requests by inverse FE, for the bridge: render::DisplayRendering on the
// bridge's own fingertip model, fed the bridge's Merkel SED as its target every scan. What
// DisplayController calls instead of the curve (display/command_request_source.h); the
// safety limiter after it is unchanged.
//
//   auto inverse = std::make_shared<InverseDisplayRequests>(config, profile, fe.merkel_rest_pad_mm());
//   DisplaySessionOptions o;  o.requests = inverse->Source();      // every scan: Render(target)
//   inverse->Deliver(published.value, &delivered_Pa);              // full FE (replay's peak)

#include <Eigen/Core>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "bridge/bridge_config.h"
#include "bridge/latency_stats.h"
#include "display/command_request_source.h"
#include "display/display_profile.h"
#include "model/fingertip_model.h"
#include "render/display_rendering.h"

namespace sedbridge::bridge {

/// What an inverse rendering precomputes, built once for fingers with the same leader model
/// and display profile and shared by them: the leader model, its contact model and the
/// display pressed on it with the influence (render::DisplayRendering). Each finger renders
/// with its own copy of the renderer (warm start, scratch; the influence, a few MB, copied
/// into it); the shared renderer is never run. Deliver (the full FE, at a replay's peak)
/// changes the contact model's state, so it holds `deliver_mutex`.
struct InverseRenderingPrecompute {
  model::FingertipModel model;
  std::unique_ptr<render::DisplayRendering> rendering;
  std::mutex deliver_mutex;
  double precompute_s = 0;  ///< wall time of the model load and the precompute [s]
};

/// The precomputes of a hand's inverse renderings, by leader model, display profile, cache
/// folder and renderer options (bridge/leader_model_cache.h does the same for the FE step).
class InverseRenderingCache {
 public:
  std::shared_ptr<InverseRenderingPrecompute> Get(const std::string& key,
                                                  const std::function<std::shared_ptr<InverseRenderingPrecompute>()>& build);
  int built() const { return built_; }
  int shared() const { return shared_; }

 private:
  std::map<std::string, std::shared_ptr<InverseRenderingPrecompute>> by_key_;
  int built_ = 0, shared_ = 0;
};

class InverseDisplayRequests {
 public:
  /// Loads config.model (the leader's finger is the bridge's model), builds its contact
  /// model (cache: config.compliance_cache_dir), the display on it and the influence (n + 1
  /// contact solves). `merkel_rest_pad_mm`: the bridge FE step's Merkel vertices, which must
  /// be the model's whole layer in its order (fe.merkel_region: layer). `progress`: a line
  /// before the precompute (null: none). Throws std::invalid_argument for a profile that
  /// cannot be rendered so or a vertex mismatch, std::runtime_error when a solve fails.
  /// `cache`: the precompute is taken from it when another finger built it for the same
  /// model and display, else built and left there (null: built for this one alone).
  InverseDisplayRequests(const BridgeConfig& config, const display::DisplayProfile& profile,
                         const Eigen::Matrix3Xd& merkel_rest_pad_mm,
                         const std::function<void(const std::string&)>& progress = {},
                         InverseRenderingCache* cache = nullptr);

  /// The commands for `field`'s SED as the target (negative SED read as 0, as the curve does).
  void Request(const display::SedField& field, std::vector<double>* requested);
  /// Request() of this object as a display::CommandRequestSource (keeps it alive).
  static display::CommandRequestSource Source(std::shared_ptr<InverseDisplayRequests> self);

  /// The SED [Pa] `commands` add to the preloaded pad by the full contact FE, per Merkel
  /// vertex (the bridge's order). False (message in error()) when the solve fails.
  bool Deliver(const std::vector<double>& commands, Eigen::VectorXd* delivered_sed_Pa);
  /// The SED [Pa] the last requested commands add to the preloaded pad by the renderer's
  /// influence model, per Merkel vertex (the bridge's order), and those commands: what the
  /// renderer's fit evaluated at its answer, so nothing is evaluated again and the renderer's
  /// state is left alone (render::InverseRenderer::AddedSed).
  void PredictedSed(Eigen::VectorXd* added_sed_Pa, std::vector<double>* commands) const;
  const std::string& error() const { return precompute_->rendering->error(); }

  int num_actuators() const { return precompute_->rendering->num_actuators(); }
  /// Wall time of the precompute, model load included [s].
  double precompute_s() const { return precompute_s_; }
  /// Wall time of each Render [ms] (the renderer's share of the limiter stage).
  const LatencyStats& render_times() const { return render_times_; }
  /// CPU time of each Render [ms]: its own cost, without the time a loaded machine kept the
  /// thread waiting.
  const LatencyStats& render_cpu_times() const { return render_cpu_times_; }
  /// Scans whose renderer did not converge within its iterations (the answer is its best).
  int64_t not_converged() const { return not_converged_; }
  /// SED evaluations of each Render (trials included: the renderer's work, without the
  /// machine's noise): the median, 99th percentile and maximum over the run's renders.
  struct EvaluationCounts {
    int64_t renders = 0;
    int median = 0, p99 = 0, max = 0;
  };
  EvaluationCounts evaluation_counts() const;

 private:
  std::shared_ptr<InverseRenderingPrecompute> precompute_;
  std::unique_ptr<render::InverseRenderer> renderer_;  // this finger's: its warm start
  Eigen::VectorXd target_Pa_;
  LatencyStats render_times_{100'000}, render_cpu_times_{100'000};
  int64_t not_converged_ = 0;
  std::vector<int64_t> evaluations_histogram_;  // [k]: renders that took k evaluations
  double precompute_s_ = 0;
};

}  // namespace sedbridge::bridge
