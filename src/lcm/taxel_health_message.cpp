#include "lcm/taxel_health_message.h"

namespace sedbridge::lcm_io {

const char* TaxelHealthName(int8_t code) {
  switch (static_cast<TaxelHealthCode>(code)) {
    case TaxelHealthCode::kOk: return "ok";
    case TaxelHealthCode::kStuckHigh: return "stuck";
    case TaxelHealthCode::kDead: return "dead";
    case TaxelHealthCode::kFrozen: return "frozen";
    case TaxelHealthCode::kDrifting: return "drifting";
  }
  return "?";
}

TaxelHealthCode TaxelHealthCodeOf(const sensors::TaxelHealth& health, int taxel) {
  switch (health.fault(taxel)) {
    case sensors::TaxelFault::kStuckHigh: return TaxelHealthCode::kStuckHigh;
    case sensors::TaxelFault::kDead: return TaxelHealthCode::kDead;
    case sensors::TaxelFault::kFrozen: return TaxelHealthCode::kFrozen;
    case sensors::TaxelFault::kHealthy: break;
  }
  return health.retare_offset_N(taxel) != 0 ? TaxelHealthCode::kDrifting : TaxelHealthCode::kOk;
}

std::string DescribeTaxelHealth(const std::vector<int8_t>& codes) {
  if (codes.empty()) return "taxel health: not reported";
  std::string masked, drifting;
  int n_masked = 0;
  for (size_t k = 0; k < codes.size(); ++k) {
    const auto code = static_cast<TaxelHealthCode>(codes[k]);
    if (code == TaxelHealthCode::kOk) continue;
    if (code == TaxelHealthCode::kDrifting) {
      drifting += (drifting.empty() ? "" : ", ") + std::to_string(k);
      continue;
    }
    ++n_masked;  // stuck, dead, frozen, or a code of a newer sender: not trusted
    masked += (masked.empty() ? "" : ", ") + std::to_string(k) + " " + TaxelHealthName(codes[k]);
  }
  const std::string total = std::to_string(codes.size());
  std::string out = n_masked == 0 ? (drifting.empty() ? "taxel health: all " + total + " ok" : "taxel health: none of " + total + " masked")
                                  : "taxel health: " + std::to_string(n_masked) + " of " + total + " masked (" + masked + ")";
  if (!drifting.empty()) out += "; drifting (re-tared): " + drifting;
  return out;
}

void SetTaxelHealth(const sensors::TaxelHealth& health, lcmt_bridge_status* s) {
  const int n = health.taxel_count();
  s->num_taxels = n;
  s->taxel_health.assign(static_cast<size_t>(n), 0);
  s->taxels_stuck = s->taxels_dead = s->taxels_frozen = s->taxels_drifting = 0;
  for (int k = 0; k < n; ++k) {
    const TaxelHealthCode code = TaxelHealthCodeOf(health, k);
    s->taxel_health[static_cast<size_t>(k)] = static_cast<int8_t>(code);
    s->taxels_stuck += code == TaxelHealthCode::kStuckHigh;
    s->taxels_dead += code == TaxelHealthCode::kDead;
    s->taxels_frozen += code == TaxelHealthCode::kFrozen;
    s->taxels_drifting += code == TaxelHealthCode::kDrifting;
  }
  const sensors::TaxelHealthCounters& c = health.counters();
  s->taxel_scans_left_out = c.masked_taxel_scans;
  s->taxels_masked_total = c.masked_frozen + c.masked_stuck + c.masked_dead;
  s->taxels_recovered = c.recovered;
  s->taxel_retares = c.retares;
}

}  // namespace sedbridge::lcm_io
