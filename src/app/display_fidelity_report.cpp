#include "app/display_fidelity_report.h"

#include <cstdio>
#include <stdexcept>

namespace sedbridge::app {

DisplayFidelityReport::DisplayFidelityReport(const std::string& model_name, fidelity::DisplayFidelityOptions options,
                                             const std::string& out)
    : fidelity_(model_name, std::move(options)), path_(out + "/display_fidelity.csv") {
  csv_.open(path_);
  if (!csv_) throw std::runtime_error("cannot write " + path_);
  csv_ << "case,display,rendering,status,actuators,delivered_peak_ratio,delivered_rel_l2,delivered_peak_offset_mm,"
          "delivered_peak_region_offset_mm,vs_asked_rel_l2,render_ms,commands_at_max,max_command_share,"
          "truth_max_sed_Pa,asked_max_sed_Pa,delivered_max_sed_Pa\n";
}

void DisplayFidelityReport::Add(const fidelity::FidelityRow& row, const fidelity::FidelityMaps& maps) {
  for (const fidelity::DisplayFidelityRow& r : fidelity_.Score(row, maps)) {
    char line[1024];
    std::snprintf(line, sizeof line, "%s,%s,%s,\"%s\",%d,%g,%g,%g,%g,%g,%g,%d,%g,%g,%g,%g\n", r.case_name.c_str(),
                  r.display.c_str(), r.rendering.c_str(), r.status.c_str(), r.actuators, r.delivered.peak_ratio,
                  r.delivered.rel_l2, r.delivered.peak_offset_mm, r.delivered.peak_region_offset_mm, r.vs_asked_rel_l2,
                  r.render_ms, r.commands_at_max, r.max_command_share, r.truth_max_sed_Pa, r.asked_max_sed_Pa,
                  r.delivered_max_sed_Pa);
    csv_ << line;
    rows_.push_back(r);
  }
  csv_.flush();
}

void DisplayFidelityReport::Print() const {
  std::printf("display fidelity: what the display delivers (full contact on the leader) against the truth, medians "
              "over the scored cases (failed: the full-contact press did not converge, not in the medians)\n"
              "%-14s %-8s %6s %6s %7s %6s %6s %7s %9s %9s %7s  %s\n",
              "display", "render", "scored", "failed", "within", "peak", "L2", "off_mm", "vs_asked", "render_ms", "at_max",
              "precompute");
  for (const fidelity::DisplayFidelitySummary& s : fidelity::SummarizeDisplayFidelity(rows_)) {
    double precompute_s = 0;
    for (const auto& d : fidelity_.displays())
      if (d.name == s.display) precompute_s = d.precompute_s;
    if (s.scored == 0) {
      std::printf("%-14s %-8s %6d %6d  (%s)\n", s.display.c_str(), s.rendering.c_str(), 0, s.deliver_failed,
                  s.status.c_str());
      continue;
    }
    std::printf("%-14s %-8s %6d %6d %7d %6.2f %6.2f %7.2f %9.2f %9.3f %7d  %.1f s\n", s.display.c_str(),
                s.rendering.c_str(), s.scored, s.deliver_failed, s.within_targets, s.peak_ratio, s.rel_l2, s.peak_offset_mm,
                s.vs_asked_rel_l2, s.render_ms, s.commands_at_max, precompute_s);
  }
  std::printf("wrote %s\n", path_.c_str());
}

}  // namespace sedbridge::app
