#pragma once
// Which rendering the bridge's display gets (config `display.rendering`), why, and the
// request source that does it: the one place replay, simulate and run decide.
//
// The rule: `curve` when asked; `inverse` when asked (refused, with the reason, where the
// display cannot be rendered so); absent: inverse wherever the display profile has a device
// model of a kind with a mechanical load on the leader (render::HasMechanicalLoad: pins now,
// every kind render::MakeDisplayOnLeader builds), the curve otherwise. Electrotactile has no
// mechanical load: always the curve.

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>

#include "bridge/bridge_config.h"
#include "bridge/inverse_display_requests.h"
#include "display/command_request_source.h"
#include "display/display_profile.h"

namespace sedbridge::bridge {

struct RenderingChoice {
  RenderingMethod method = RenderingMethod::kCurve;
  std::string why;  ///< e.g. "display.rendering not set: pin_6x4 has a device model ..."
};

/// The rendering `config` gives `profile` and why, building nothing. Throws
/// std::invalid_argument when `display.rendering: inverse` is asked of a display that
/// cannot be rendered so (the message says why and names the config file).
RenderingChoice ChooseRendering(const BridgeConfig& config, const display::DisplayProfile& profile);

/// The chosen rendering, built.
struct DisplayRequests {
  RenderingChoice choice;
  std::shared_ptr<InverseDisplayRequests> inverse;  ///< null with the curve

  /// The display controller's request source (empty: the curve).
  display::CommandRequestSource source() const {
    return inverse ? InverseDisplayRequests::Source(inverse) : display::CommandRequestSource{};
  }
  /// "display rendering: inverse FE (why)" or "display rendering: curve (why)".
  std::string Describe() const;
};

/// ChooseRendering, then the inverse renderer's precompute when it is chosen (see
/// InverseDisplayRequests; `progress` gets its startup lines).
/// `renderings`: a hand's shared inverse-rendering precomputes (InverseRenderingCache; null:
/// built for this display alone).
DisplayRequests MakeDisplayRequests(const BridgeConfig& config, const display::DisplayProfile& profile,
                                    const Eigen::Matrix3Xd& merkel_rest_pad_mm,
                                    const std::function<void(const std::string&)>& progress = {},
                                    InverseRenderingCache* renderings = nullptr);

}  // namespace sedbridge::bridge
