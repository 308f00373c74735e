#pragma once
// Taxel health told as a story: when each taxel was masked, why, and when it came back, from
// a TaxelHealth observed after every scan (`sedbridge decode` prints it).

#include <cstdint>
#include <string>
#include <vector>

#include "sensors/taxel_health.h"

namespace sedbridge::sensors {

struct TaxelHealthEpisode {
  int taxel = 0;
  TaxelFault fault = TaxelFault::kHealthy;
  double from_s = 0;       ///< first scan masked [s since the first scan observed]
  double to_s = -1;        ///< first scan back (-1: still masked at the last scan)
  int64_t scans = 0;       ///< scans masked
};

class TaxelHealthEpisodes {
 public:
  /// After health.Apply(scan) of the scan at t_s.
  void Observe(const TaxelHealth& health, double t_s);
  const std::vector<TaxelHealthEpisode>& episodes() const { return episodes_; }
  /// "taxel health: no taxel masked" or "taxel health: 1 masked now (5 stuck high)" and a
  /// line per episode: "  taxel 5 stuck high: masked 1.230 s to the end (118 scans)".
  std::string Report() const;

 private:
  std::vector<int> open_;  // per taxel: index into episodes_ of its open episode, -1 none
  std::vector<TaxelHealthEpisode> episodes_;
  double last_s_ = 0;
};

}  // namespace sedbridge::sensors
