#include "sensors/taxel_health_episodes.h"

#include <cstdio>

namespace sedbridge::sensors {

void TaxelHealthEpisodes::Observe(const TaxelHealth& health, double t_s) {
  const int n = health.taxel_count();
  if (static_cast<int>(open_.size()) != n) open_.assign(static_cast<size_t>(n), -1);
  last_s_ = t_s;
  for (int k = 0; k < n; ++k) {
    int& open = open_[static_cast<size_t>(k)];
    const TaxelFault fault = health.fault(k);
    if (open >= 0 && episodes_[static_cast<size_t>(open)].fault != fault) {
      episodes_[static_cast<size_t>(open)].to_s = t_s;  // back, or masked for another reason
      open = -1;
    }
    if (fault == TaxelFault::kHealthy) continue;
    if (open < 0) {
      open = static_cast<int>(episodes_.size());
      episodes_.push_back({k, fault, t_s, -1, 0});
    }
    ++episodes_[static_cast<size_t>(open)].scans;
  }
}

std::string TaxelHealthEpisodes::Report() const {
  std::string now;
  for (size_t k = 0; k < open_.size(); ++k)
    if (open_[k] >= 0)
      now += (now.empty() ? "" : ", ") + std::to_string(k) + " " + ToString(episodes_[static_cast<size_t>(open_[k])].fault);
  std::string out = episodes_.empty() ? "taxel health: no taxel masked"
                                      : "taxel health: " + std::to_string(episodes_.size()) + " masking" +
                                            (episodes_.size() == 1 ? "" : "s") + "; masked at the end: " +
                                            (now.empty() ? "none" : now);
  out += "\n";
  char line[160];
  for (const TaxelHealthEpisode& e : episodes_) {
    if (e.to_s >= 0)
      std::snprintf(line, sizeof line, "  taxel %d %s: masked %.3f to %.3f s (%lld scans)\n", e.taxel, ToString(e.fault),
                    e.from_s, e.to_s, static_cast<long long>(e.scans));
    else
      std::snprintf(line, sizeof line, "  taxel %d %s: masked %.3f s to the end (%lld scans)\n", e.taxel,
                    ToString(e.fault), e.from_s, static_cast<long long>(e.scans));
    out += line;
  }
  return out;
}

}  // namespace sedbridge::sensors
