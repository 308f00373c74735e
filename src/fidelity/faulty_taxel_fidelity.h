#pragma once
// The fidelity benchmark's faulty-taxel set (`sedbridge fidelity --faulty-taxels`):
// every press with each single taxel dead, and with each single taxel stuck high, in turn,
// lying from the press's first scan:
//   dead        the taxel reads no load: it repeats, on all its axes, the readings it had in
//               the press's quiet scans before the contact (noise around zero, so that it is
//               not simply frozen);
//   stuck high  the same plus a constant normal load (stuck_N, 2.5 N by default: the issue's
//               report), as tests/bridge/faulty_taxel_replay_test.cpp edits the example log.
// Each faulty press goes through taxel health (sensors/taxel_health.h) scan by scan as the
// bridge runs it, and the judged scans are scored at the peak exactly as the healthy
// benchmark scores a press (FidelityBenchmark::Run: reconstruction warm through the press,
// the pressure map where the fit falls back, the leader press, the truth at the peak's load).
// For the stuck taxel, also: the scans before the contact that the bridge would not answer
// with "no contact" (the reconstruction finds a contact or falls back to the pressure map):
// each of them would drive the display (target: none).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "contact/contact_estimate.h"
#include "contact/reconstruction_options.h"
#include "fidelity/fidelity_benchmark.h"
#include "fidelity/fidelity_case.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::fidelity {

enum class TaxelFaultKind { kDead, kStuckHigh };
/// "dead", "stuck".
const char* ToString(TaxelFaultKind kind);

/// Scans before the first one whose true normal load is above 0 (at least 1 when the press
/// has scans): the quiet start a dead taxel repeats.
size_t QuietScans(const FidelityCase& press);

/// `press` with `taxel` lying from its first scan (see above). stuck_N: the stuck-high
/// taxel's extra normal reading [N].
FidelityCase WithFaultyTaxel(const FidelityCase& press, const sensors::SensorProfile& profile, int taxel,
                             TaxelFaultKind kind, double stuck_N = 2.5);

/// `press`'s scans as taxel health hands them on (each judged after those before it, from a
/// fresh TaxelHealth), and its summary at the end.
FidelityCase JudgedByTaxelHealth(const FidelityCase& press, const sensors::SensorProfile& profile,
                                 std::string* health_summary = nullptr);

/// The scan FidelityBenchmark::Run scores: the largest sum of valid normal readings.
size_t PeakScan(const FidelityCase& press, const sensors::SensorProfile& profile);

struct FaultyTaxelRow {
  std::string press;
  int taxel = 0;
  TaxelFaultKind kind = TaxelFaultKind::kDead;
  FidelityRow row;                   ///< the faulty press scored as the benchmark scores it
  bool healthy_within = false;       ///< the same press without the fault was within the targets
  bool within = false;               ///< truth valid and the delivered SED within all three targets
  bool taxel_left_out_at_peak = false;  ///< taxel health had left the taxel out at the peak scan
  int left_out_at_peak = 0;          ///< taxels left out at the peak scan
  /// How the reconstruction at the peak scan weighed the taxel (kLoneMisfit: the fit left it out).
  contact::TaxelUse fit_use_at_peak = contact::TaxelUse::kUsed;
  int quiet_scans = 0;               ///< scans before the contact
  int quiet_scans_driving = 0;       ///< of those, answered other than "no contact" (display driven)
  int healthy_quiet_scans_driving = 0;  ///< the same without the fault
  std::string health;                ///< taxel health's summary at the end of the press
};

/// How bad a row is, for the worst cases: a row outside the targets before one inside, then
/// by |log peak ratio| + rel. L2 of the delivered SED.
double Badness(const FaultyTaxelRow& r);

struct FaultyTaxelOptions {
  double stuck_N = 2.5;
  std::vector<int> taxels;  ///< empty: every taxel of the profile
  std::vector<TaxelFaultKind> kinds = {TaxelFaultKind::kDead, TaxelFaultKind::kStuckHigh};
  /// After each press: (presses done, presses in all, that press's rows).
  std::function<void(size_t, size_t, const std::vector<FaultyTaxelRow>&)> progress;
};

/// Every press of `presses` with each taxel and fault of `options`, scored by `bench` (whose
/// reconstruction options are `reconstruction`, for the quiet-scan count).
std::vector<FaultyTaxelRow> RunFaultyTaxelSet(FidelityBenchmark& bench, const std::vector<FidelityCase>& presses,
                                              const sensors::SensorProfile& profile,
                                              const contact::ReconstructionOptions& reconstruction,
                                              const FaultyTaxelOptions& options = {});

/// Per fault: rows, scored (truth valid), within the targets, and scans before the contact
/// that drive the display.
struct FaultyTaxelTally {
  int rows = 0, scored = 0, within = 0, healthy_within = 0;
  int quiet_scans = 0, quiet_scans_driving = 0, rows_driving_before_contact = 0;
  int healthy_quiet_scans_driving = 0;  ///< quiet_scans_driving of the same presses without the fault
  double WithinShare() const { return scored > 0 ? double(within) / scored : 0.0; }
};
FaultyTaxelTally Tally(const std::vector<FaultyTaxelRow>& rows, TaxelFaultKind kind);

/// faulty_taxels.csv: one row per press, taxel and fault.
void WriteFaultyTaxelCsv(const std::string& path, const std::vector<FaultyTaxelRow>& rows);
/// The summary: per fault, the share within the targets (the target: >= 90 % with any one
/// taxel dead), the scans before the contact that drive the display, and the `worst` worst rows.
void PrintFaultyTaxelSummary(const std::vector<FaultyTaxelRow>& rows, int worst = 10);

}  // namespace sedbridge::fidelity
