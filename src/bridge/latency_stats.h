#pragma once
// Per-scan latency (scan receive time -> command published) summarised as median / p90 /
// p99 / max, over a sliding report window (for BRIDGE_STATUS) and over the whole run (for
// the exit summary). Not thread-safe: the solver thread owns it.

#include <cstdint>
#include <vector>

namespace sedbridge::bridge {

struct LatencySummary {
  int64_t count = 0;
  double p50_ms = 0, p90_ms = 0, p99_ms = 0, max_ms = 0, mean_ms = 0;
};

/// Percentile by nearest rank (q in [0, 1]) of `values` (reordered in place); 0 when empty.
double Percentile(std::vector<float>& values, double q);

class LatencyStats {
 public:
  /// `max_run_samples` bounds the memory of the whole-run summary (4 bytes a sample); past
  /// it, every second sample is discarded and only every 2nd/4th/... later sample kept, so the
  /// summary stays a uniform subsample of the run.
  explicit LatencyStats(int64_t max_run_samples = 4'000'000);

  /// Adds one latency [us] (negative values, from clocks that disagree, count as 0).
  void Add(int64_t latency_us);
  /// Adds one duration [ms] (stage times, below the microsecond; negative counts as 0).
  void AddMs(double latency_ms);
  /// Summary of the samples since the last ResetWindow().
  LatencySummary Window() const;
  void ResetWindow() { window_.clear(); }
  /// Summary of the whole run (max and count are exact; percentiles from the kept samples).
  LatencySummary Run() const;

 private:
  static LatencySummary Summarize(std::vector<float> values, int64_t count, double max_ms, double sum_ms);

  std::vector<float> window_;
  std::vector<float> run_;
  int64_t max_run_samples_;
  int64_t keep_every_ = 1, seen_ = 0, count_ = 0;
  double max_ms_ = 0, sum_ms_ = 0;
};

}  // namespace sedbridge::bridge
