#include "bridge/latency_stats.h"

#include <algorithm>
#include <cmath>

namespace sedbridge::bridge {

double Percentile(std::vector<float>& values, double q) {
  if (values.empty()) return 0;
  const size_t n = values.size();
  size_t k = static_cast<size_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(n)));
  k = std::clamp<size_t>(k, 1, n) - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

LatencyStats::LatencyStats(int64_t max_run_samples) : max_run_samples_(std::max<int64_t>(2, max_run_samples)) {}

void LatencyStats::Add(int64_t latency_us) { AddMs(static_cast<double>(std::max<int64_t>(0, latency_us)) * 1e-3); }

void LatencyStats::AddMs(double latency_ms) {
  const double ms = std::max(0.0, latency_ms);
  window_.push_back(static_cast<float>(ms));
  ++count_;
  sum_ms_ += ms;
  max_ms_ = std::max(max_ms_, ms);
  if (seen_++ % keep_every_ != 0) return;
  run_.push_back(static_cast<float>(ms));
  if (static_cast<int64_t>(run_.size()) >= max_run_samples_) {
    size_t j = 0;
    for (size_t i = 0; i < run_.size(); i += 2) run_[j++] = run_[i];
    run_.resize(j);
    keep_every_ *= 2;
  }
}

LatencySummary LatencyStats::Summarize(std::vector<float> values, int64_t count, double max_ms, double sum_ms) {
  LatencySummary s;
  s.count = count;
  if (values.empty()) return s;
  s.max_ms = max_ms;
  s.mean_ms = count > 0 ? sum_ms / static_cast<double>(count) : 0;
  s.p50_ms = Percentile(values, 0.50);
  s.p90_ms = Percentile(values, 0.90);
  s.p99_ms = Percentile(values, 0.99);
  return s;
}

LatencySummary LatencyStats::Window() const {
  double max_ms = 0, sum = 0;
  for (float v : window_) max_ms = std::max<double>(max_ms, v), sum += v;
  return Summarize(window_, static_cast<int64_t>(window_.size()), max_ms, sum);
}

LatencySummary LatencyStats::Run() const { return Summarize(run_, count_, max_ms_, sum_ms_); }

}  // namespace sedbridge::bridge
