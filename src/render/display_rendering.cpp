#include "render/display_rendering.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <utility>

#include "render/leader_pad.h"
#include "render/reduced_vertex_strain.h"

namespace sedbridge::render {

Eigen::VectorXd MaxCommands(const display::DisplayProfile& profile) {
  const std::vector<double>& m = profile.safety.max_per_actuator;
  Eigen::VectorXd max = Eigen::Map<const Eigen::VectorXd>(m.data(), Eigen::Index(m.size()));
  if (max.size() == 0) max.setConstant(Eigen::Index(profile.size()), profile.safety.max);
  return max;
}

DisplayRendering::DisplayRendering(const model::FingertipModel& leader_model, const display::DisplayProfile& profile,
                                   DisplayRenderingOptions options) {
  const auto start = std::chrono::steady_clock::now();
  if (!profile.has_device_model())
    throw std::invalid_argument("display rendering: profile '" + profile.name +
                                "' has no device model (key device); it renders by the curve only");
  scene::FingertipComplianceOptions leader_options;
  leader_options.contact.cache_dir = options.cache_dir;
  leader_ = std::make_unique<scene::FingertipCompliance>(leader_model, DisplayLeaderOptions(leader_options));
  // Refused before the precompute: an actuator off the pad would touch no contact point.
  CheckDisplayFitsLeaderPad(profile, *leader_);
  display_ = MakeDisplayOnLeader(*leader_, profile.device);
  const double reference = options.reference_command > 0 ? options.reference_command : display_->default_reference_command();
  ElementStrainInfluence elements = display_->Influence(reference);
  if (options.fit_reduction > 0 && !DisplayInfluence::EvaluatedByVertexForms(elements)) {
    // Kept only where it is smaller: a vertex averaging few elements shared with its
    // neighbours can need more rows than the elements had.
    ElementStrainInfluence reduced = ReduceStrainPerVertex(elements, options.fit_reduction);
    if (reduced.mu_Pa.size() < elements.mu_Pa.size()) elements = std::move(reduced);
  }
  DisplayInfluence influence(elements, options.prune_relative);
  preload_sed_Pa_ = influence.preload_sed_Pa();
  renderer_ = std::make_unique<InverseRenderer>(std::move(influence), MaxCommands(profile), options.renderer);
  precompute_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool DisplayRendering::Deliver(const Eigen::VectorXd& commands, Eigen::VectorXd& delivered_sed_Pa) {
  if (!display_->Press(commands, delivered_sed_Pa)) return false;
  delivered_sed_Pa -= preload_sed_Pa_;
  return true;
}

}  // namespace sedbridge::render
