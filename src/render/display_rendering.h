#pragma once
// The inverse rendering of one display on the leader's finger, in one object: the leader's
// contact model (face contact: pins and holes are narrower than the skin-node spacing),
// the display pressed on it (render/display_on_leader.h), its linear influence and the
// inverse renderer (render/inverse_renderer.h). What the bridge, the fidelity benchmark and
// the tools share:
//
//   render::DisplayRendering rendering(model, profile, options);   // precompute: n + 1 presses
//   const Eigen::VectorXd& u = rendering.Render(target_sed_Pa);     // every scan, microseconds
//   Eigen::VectorXd delivered_Pa;
//   rendering.Deliver(u, delivered_Pa);                             // full FE, for the benchmark
//
// SED vectors are per vertex of the leader's Merkel layer (model.merkel_nodes order, as the
// bridge's FeStep computes it). The target is the SED the object adds to the finger at
// rest; Deliver answers the SED the commands add to the preloaded pad, the same measure.

#include <Eigen/Core>
#include <memory>
#include <string>

#include "display/display_profile.h"
#include "model/fingertip_model.h"
#include "render/display_on_leader.h"
#include "render/inverse_renderer.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::render {

struct DisplayRenderingOptions {
  /// Compliance precompute cache folder of the leader's contact model ("" = none).
  std::string cache_dir;
  /// Influence reference command [profile unit]; 0 = the display's default.
  double reference_command = 0;
  /// Elements whose strain change stays below this fraction of the largest are held at the
  /// preload's strain (DisplayInfluence).
  double prune_relative = 1e-4;
  /// Where the influence is evaluated element by element (pins; more than 32 actuators):
  /// > 0 describes it per vertex in the leading directions of the commands' strain changes,
  /// leaving out at most this share of their energy at any vertex
  /// (render/reduced_vertex_strain.h); 0: the elements as they are. 1e-2: on model B a
  /// render 4-7 times cheaper (760 rows of six instead of 5228) with the fit as close to
  /// its target, judged by the elements (docs/display-rendering.md).
  double fit_reduction = 1e-2;
  InverseRendererOptions renderer;
};

class DisplayRendering {
 public:
  /// @param leader_model the leader's fingertip model (must outlive this object)
  /// @param profile      a display profile with a device model (suction or pin)
  /// Throws std::invalid_argument for a profile without a device model (electrotactile
  /// included), DisplayDoesNotFitPad (an std::invalid_argument naming the profile's
  /// file:line:column) for one whose footprints leave the leader's pad
  /// (render/leader_pad.h), std::runtime_error when a press of the precompute fails.
  DisplayRendering(const model::FingertipModel& leader_model, const display::DisplayProfile& profile,
                   DisplayRenderingOptions options = {});

  int num_actuators() const { return display_->num_actuators(); }
  /// Commands [profile unit, each in [0, the profile's per-actuator maximum]] for the target
  /// SED [Pa]; warm-started from the last call. See InverseRenderer::Render.
  const Eigen::VectorXd& Render(const Eigen::VectorXd& target_sed_Pa) { return renderer_->Render(target_sed_Pa); }
  const RenderResult& last() const { return renderer_->last(); }
  /// The SED [Pa] `commands` add to the preloaded pad (full contact minus the preload's own
  /// SED), per Merkel vertex. False (message in error()) if the contact solve fails.
  bool Deliver(const Eigen::VectorXd& commands, Eigen::VectorXd& delivered_sed_Pa);
  /// The SED of the preloaded pad with every actuator off [Pa] (full contact).
  const Eigen::VectorXd& preload_sed_Pa() const { return preload_sed_Pa_; }
  /// The influence the renderer fits on (reduced per vertex where options.fit_reduction
  /// applies: then its SED is that description's, not the elements').
  const DisplayInfluence& influence() const { return renderer_->influence(); }
  InverseRenderer& renderer() { return *renderer_; }
  DisplayOnLeader& display() { return *display_; }
  /// Wall time of the precompute (compliance model, preload, influence) [s].
  double precompute_s() const { return precompute_s_; }
  const std::string& error() const { return display_->error(); }

 private:
  std::unique_ptr<scene::FingertipCompliance> leader_;
  std::unique_ptr<DisplayOnLeader> display_;
  std::unique_ptr<InverseRenderer> renderer_;
  Eigen::VectorXd preload_sed_Pa_;
  double precompute_s_ = 0;
};

/// Each actuator's maximum [profile unit]: safety.max_per_actuator (filled by the loader).
Eigen::VectorXd MaxCommands(const display::DisplayProfile& profile);

}  // namespace sedbridge::render
