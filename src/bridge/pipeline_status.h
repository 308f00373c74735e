#pragma once
// Typed health of the bridge pipeline: the fault state BRIDGE_STATUS carries, and why a scan
// was not stepped, with a counter per reason (MuJoCo's mjWARN_* warnings with counts).

#include <array>
#include <cstdint>
#include <string>

namespace sedbridge::bridge {

/// BRIDGE_STATUS fault_state (the wire value is the enum's).
enum class FaultState : int8_t {
  kOk = 0,
  kDegraded = 1,  ///< warnings: invalid taxels filled, CAN error-passive
  kFault = 2,     ///< display held at zero: scan rejected, CAN bus-off, shut down
};
/// "ok", "degraded", "fault".
constexpr const char* ToString(FaultState state) {
  switch (state) {
    case FaultState::kOk: return "ok";
    case FaultState::kDegraded: return "degraded";
    case FaultState::kFault: return "fault";
  }
  return "?";
}

/// Why a scan was not stepped (the detail text goes with it in ScanOutcome::problem).
enum class RejectReason {
  kWrongTaxelCount,      ///< the scan's taxel count differs from the profile's
  kMissingShear,         ///< a 3-axis profile and a scan without shear
  kTooManyInvalidTaxels, ///< above conditioning.max_invalid_fraction
  kFeStepFailed,         ///< the FE step gave no usable SED (non-finite, bad solve)
  kSedSizeMismatch,      ///< the FE step's SED does not match the Merkel layer
};
constexpr int kNumRejectReasons = 5;

/// Snake-case name, e.g. "too_many_invalid_taxels".
constexpr const char* ToString(RejectReason reason) {
  switch (reason) {
    case RejectReason::kWrongTaxelCount: return "wrong_taxel_count";
    case RejectReason::kMissingShear: return "missing_shear";
    case RejectReason::kTooManyInvalidTaxels: return "too_many_invalid_taxels";
    case RejectReason::kFeStepFailed: return "fe_step_failed";
    case RejectReason::kSedSizeMismatch: return "sed_size_mismatch";
  }
  return "?";
}

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
  for (int i = 0; i < kNumRejectReasons; ++i) {
    if (counters.count[size_t(i)] == 0) continue;
    line += (line.empty() ? "" : ", ") + std::string(ToString(static_cast<RejectReason>(i))) + " " +
            std::to_string(counters.count[size_t(i)]);
  }
  return line.empty() ? "none" : line;
}

}  // namespace sedbridge::bridge
