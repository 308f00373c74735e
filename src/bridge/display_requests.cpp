#include "bridge/display_requests.h"

#include <cstdio>
#include <stdexcept>

#include "render/display_on_leader.h"

namespace sedbridge::bridge {
namespace {

// Why `profile` cannot be rendered by inverse FE under `config` ("" when it can).
std::string WhyNotInverse(const BridgeConfig& config, const display::DisplayProfile& profile) {
  const std::string kind = display::ToString(profile.kind);
  if (profile.kind == display::DisplayKind::kElectrotactile)
    return profile.name + " is electrotactile: no mechanical load on the leader, no SED for the inverse FE to "
                          "fit (the curve gives its commands; replay and simulate read them against the SA1 rate "
                          "estimate, peak_sa1_rate_estimate.csv)";
  if (!profile.has_device_model()) return profile.name + " has no device model (profile key `device`)";
  if (!render::HasMechanicalLoad(profile.kind))
    return "no model of a " + kind + " display's load on the leader yet (render::MakeDisplayOnLeader)";
  if (config.merkel_region == MerkelRegion::kDisplay)
    return "fe.merkel_region: display computes only the vertices the curve samples; the inverse renderer fits the "
           "layer under the display";
  return "";
}

}  // namespace

RenderingChoice ChooseRendering(const BridgeConfig& config, const display::DisplayProfile& profile) {
  RenderingChoice c;
  if (config.display_rendering == RenderingMethod::kCurve) {
    c.why = "display.rendering: curve";
    return c;
  }
  const std::string why_not = WhyNotInverse(config, profile);
  if (config.display_rendering == RenderingMethod::kInverse) {
    if (!why_not.empty())
      throw std::invalid_argument((config.file.empty() ? std::string("bridge config") : config.file) +
                                  ": display.rendering: inverse: " + why_not + "; use display.rendering: curve");
    c.method = RenderingMethod::kInverse;
    c.why = "display.rendering: inverse";
    return c;
  }
  if (!why_not.empty()) {
    c.why = "display.rendering not set, and inverse is not possible: " + why_not;
    return c;
  }
  c.method = RenderingMethod::kInverse;
  c.why = "display.rendering not set: " + profile.name + " has a device model with a mechanical load on the leader";
  return c;
}

std::string DisplayRequests::Describe() const {
  std::string s = "display rendering: ";
  s += choice.method == RenderingMethod::kInverse ? "inverse FE" : "curve";
  s += " (" + choice.why + ")";
  if (inverse) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "; precompute %.1f s", inverse->precompute_s());
    s += buf;
  }
  return s;
}

DisplayRequests MakeDisplayRequests(const BridgeConfig& config, const display::DisplayProfile& profile,
                                    const Eigen::Matrix3Xd& merkel_rest_pad_mm,
                                    const std::function<void(const std::string&)>& progress,
                                    InverseRenderingCache* renderings) {
  DisplayRequests r;
  r.choice = ChooseRendering(config, profile);
  if (r.choice.method == RenderingMethod::kInverse)
    r.inverse = std::make_shared<InverseDisplayRequests>(config, profile, merkel_rest_pad_mm, progress, renderings);
  return r;
}

}  // namespace sedbridge::bridge
