#include "render/leader_pad.h"

#include <algorithm>
#include <limits>

namespace sedbridge::render {

display::PadExtent LeaderPadExtent(const scene::FingertipCompliance& leader) {
  const model::FingertipModel& m = leader.model();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  display::PadExtent pad{kInf, -kInf, kInf, -kInf};
  for (const int node : leader.contact().candidate_nodes()) {
    const Eigen::Vector3d p_mm = m.pad_frame.ToPad(m.soft.rest_positions_m.col(node)) * 1e3;
    pad.x_min_mm = std::min(pad.x_min_mm, p_mm.x());
    pad.x_max_mm = std::max(pad.x_max_mm, p_mm.x());
    pad.y_min_mm = std::min(pad.y_min_mm, p_mm.y());
    pad.y_max_mm = std::max(pad.y_max_mm, p_mm.y());
  }
  return pad;
}

void CheckDisplayFitsLeaderPad(const display::DisplayProfile& profile, const scene::FingertipCompliance& leader) {
  const std::string why = display::CheckDeviceFitsPad(profile, LeaderPadExtent(leader));
  if (!why.empty())
    throw DisplayDoesNotFitPad(why + ": the candidate contact patch of model " + leader.model().name +
                               " (skin facing the pad); an actuator beyond it touches no contact point");
}

}  // namespace sedbridge::render
