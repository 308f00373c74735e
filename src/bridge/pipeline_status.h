#pragma once
// Typed health of the bridge pipeline: the fault state BRIDGE_STATUS carries, and why a scan
// was not stepped, with a counter per reason (MuJoCo's mjWARN_* warnings with counts).

#include <array>
#include <cstdint>
#include <string>

#include "common/enum_names.h"

namespace sedbridge::bridge {

/// BRIDGE_STATUS fault_state (the wire value is the enum's).
enum class FaultState : int8_t {
  kOk = 0,
  kDegraded = 1,  ///< warnings: invalid taxels filled, CAN error-passive
  kFault = 2,     ///< display held at zero: scan rejected, CAN bus-off, shut down
};
/// "ok", "degraded", "fault" (the one name table, common/enum_names.h).
inline const config::EnumNames<FaultState>& NamesOf(FaultState) {
  static const config::EnumNames<FaultState> names{
      {FaultState::kOk, "ok"}, {FaultState::kDegraded, "degraded"}, {FaultState::kFault, "fault"}};
  return names;
}
inline const char* ToString(FaultState state) { return config::NameCStrOf(state); }

/// Why a scan was not stepped (the detail text goes with it in ScanOutcome::problem).
enum class RejectReason {
  kWrongTaxelCount,      ///< the scan's taxel count differs from the profile's
  kMissingShear,         ///< a 3-axis profile and a scan without shear
  kTooManyInvalidTaxels, ///< above conditioning.max_invalid_fraction
  kFeStepFailed,         ///< the FE step gave no usable SED (non-finite, bad solve)
  kSedSizeMismatch,      ///< the FE step's SED does not match the Merkel layer
};
constexpr int kNumRejectReasons = 5;

/// Snake-case names, e.g. "too_many_invalid_taxels", in enum order.
inline const config::EnumNames<RejectReason>& NamesOf(RejectReason) {
  static const config::EnumNames<RejectReason> names{
      {RejectReason::kWrongTaxelCount, "wrong_taxel_count"},
      {RejectReason::kMissingShear, "missing_shear"},
      {RejectReason::kTooManyInvalidTaxels, "too_many_invalid_taxels"},
      {RejectReason::kFeStepFailed, "fe_step_failed"},
      {RejectReason::kSedSizeMismatch, "sed_size_mismatch"}};
  return names;
}
inline const char* ToString(RejectReason reason) { return config::NameCStrOf(reason); }

/// Rejected scans per reason since start.
struct RejectCounters {
  std::array<int64_t, kNumRejectReasons> count{};

  int64_t& operator[](RejectReason reason) { return count[static_cast<size_t>(reason)]; }
  int64_t operator[](RejectReason reason) const { return count[static_cast<size_t>(reason)]; }
  int64_t total() const {
    int64_t sum = 0;
    for (int64_t c : count) sum += c;
    return sum;
  }
};

/// "too_many_invalid_taxels 3, fe_step_failed 1": the reasons with a count > 0; "none".
inline std::string FormatRejectCounters(const RejectCounters& counters) {
  std::string line;
  for (const auto& [reason, name] : NamesOf(RejectReason{})) {
    if (counters[reason] == 0) continue;
    line += (line.empty() ? "" : ", ") + std::string(name) + " " + std::to_string(counters[reason]);
  }
  return line.empty() ? "none" : line;
}

}  // namespace sedbridge::bridge
