#pragma once
// sensors::TaxelHealth -> the taxel-health fields of lcmt_bridge_status (channel
// BRIDGE_STATUS): each taxel's state and the counts, so that a lying taxel is said, not hidden.

#include <cstdint>
#include <string>
#include <vector>

#include "sedbridge/lcmt_bridge_status.hpp"
#include "sensors/taxel_health.h"

namespace sedbridge::lcm_io {

/// lcmt_bridge_status::taxel_health[k]: the state of taxel k at the report.
enum class TaxelHealthCode : int8_t {
  kOk = 0,
  kStuckHigh = 1,  ///< masked
  kDead = 2,       ///< masked
  kFrozen = 3,     ///< masked
  kDrifting = 4,   ///< used, re-tared (its baseline taken off)
};
/// "ok", "stuck", "dead", "frozen", "drifting"; "?" for a code outside the enum (a newer sender).
const char* TaxelHealthName(int8_t code);

/// Taxel k's code: its fault when masked, else drifting when a re-tare took an offset off it.
TaxelHealthCode TaxelHealthCodeOf(const sensors::TaxelHealth& health, int taxel);

/// One line of lcmt_bridge_status::taxel_health[] for people (display-view): "taxel health:
/// all 16 ok", or "taxel health: 2 of 16 masked (5 stuck, 9 dead)", with "; drifting
/// (re-tared): 3" where re-tares took a baseline off ("taxel health: not reported" when empty).
std::string DescribeTaxelHealth(const std::vector<int8_t>& codes);

/// Fills num_taxels, taxel_health[], the per-state counts and the counters since start.
void SetTaxelHealth(const sensors::TaxelHealth& health, lcmt_bridge_status* status);

}  // namespace sedbridge::lcm_io
