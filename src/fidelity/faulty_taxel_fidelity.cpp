#include "fidelity/faulty_taxel_fidelity.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "contact/contact_reconstruction.h"
#include "sensors/calibration_press.h"
#include "sensors/taxel_health.h"

namespace sedbridge::fidelity {

const char* ToString(TaxelFaultKind kind) { return kind == TaxelFaultKind::kDead ? "dead" : "stuck"; }

size_t QuietScans(const FidelityCase& press) {
  size_t n = 0;
  while (n < press.scans.size() && n < press.load_N.size() && !(press.load_N[n].z() > 0)) ++n;
  return press.scans.empty() ? 0 : std::max<size_t>(n, 1);
}

FidelityCase WithFaultyTaxel(const FidelityCase& press, const sensors::SensorProfile& profile, int taxel,
                             TaxelFaultKind kind, double stuck_N) {
  FidelityCase c = press;
  c.name = press.name + "_t" + std::to_string(taxel) + "_" + ToString(kind);
  const size_t quiet = QuietScans(press);
  const size_t k = size_t(taxel);
  const int axes = profile.axes, normal = profile.NormalAxis();
  const double area_m2 = profile.taxel_area_mm2() * 1e-6;
  // Raw counts of stuck_N on the normal axis, in the calibration's sign.
  const double scale = profile.calibration.scale_per_count[size_t(normal)];
  const auto stuck_counts = static_cast<int32_t>(
      std::lround((scale < 0 ? -1 : 1) * stuck_N / sensors::NewtonsPerCount(profile, taxel, normal)));
  for (size_t i = 0; i < c.scans.size(); ++i) {
    sensors::Scan& s = c.scans[i];
    const sensors::Scan& q = press.scans[i % quiet];  // the taxel's quiet readings, repeated
    for (int a = 0; a < axes; ++a) s.raw_counts[k * size_t(axes) + size_t(a)] = q.raw_counts[k * size_t(axes) + size_t(a)];
    s.force_N[k] = q.force_N[k];
    s.pressure_Pa[k] = q.pressure_Pa[k];
    if (!s.shear_x_Pa.empty()) s.shear_x_Pa[k] = q.shear_x_Pa[k], s.shear_y_Pa[k] = q.shear_y_Pa[k];
    s.valid[k] = q.valid[k];
    s.flags[k] = q.flags[k];
    if (kind == TaxelFaultKind::kStuckHigh) {
      s.raw_counts[k * size_t(axes) + size_t(normal)] += stuck_counts;
      s.force_N[k] += stuck_N;
      s.pressure_Pa[k] += stuck_N / area_m2;
    }
  }
  return c;
}

FidelityCase JudgedByTaxelHealth(const FidelityCase& press, const sensors::SensorProfile& profile,
                                 std::string* health_summary) {
  FidelityCase judged = press;
  sensors::TaxelHealth health(profile);
  for (size_t i = 0; i < press.scans.size(); ++i) judged.scans[i] = health.Apply(press.scans[i]);
  if (health_summary) *health_summary = health.Summary();
  return judged;
}

size_t PeakScan(const FidelityCase& press, const sensors::SensorProfile& profile) {
  size_t peak = 0;
  double best = -1;
  for (size_t i = 0; i < press.scans.size(); ++i) {
    const Eigen::VectorXd r = sensors::ScanReadings_N(press.scans[i], profile);
    double z = 0;
    for (Eigen::Index k = 2; k < r.size(); k += 3) z += r[k];
    if (z > best) best = z, peak = i;
  }
  return peak;
}

double Badness(const FaultyTaxelRow& r) {
  const MethodError& e = r.row.recon_error;
  const double ratio = e.peak_ratio > 0 ? std::abs(std::log(e.peak_ratio)) : 10.0;
  return (r.within ? 0.0 : 100.0) + std::min(ratio, 10.0) + e.rel_l2;
}

namespace {

// The reconstruction through the judged press to `last`, as the benchmark runs it: the scans
// before the contact it answers with something other than "no contact" (each drives the
// display), and how it weighed `taxel` at `last`.
struct ReconstructedPress {
  int quiet_driving = 0;
  contact::TaxelUse use_at_last = contact::TaxelUse::kUsed;
};
ReconstructedPress Reconstruct(const FidelityCase& judged, size_t quiet, size_t last, int taxel,
                               const sensors::SensorProfile& profile,
                               const contact::ReconstructionOptions& reconstruction) {
  contact::ContactReconstructor recon(profile, reconstruction);
  ReconstructedPress r;
  for (size_t i = 0; i <= last && i < judged.scans.size(); ++i) {
    const contact::ContactEstimate& e = recon.Reconstruct(judged.scans[i]);
    if (i < quiet) r.quiet_driving += e.contact || !e.ok;
    if (i == last && size_t(taxel) < e.taxel_use.size()) r.use_at_last = e.taxel_use[size_t(taxel)];
  }
  return r;
}

}  // namespace

std::vector<FaultyTaxelRow> RunFaultyTaxelSet(FidelityBenchmark& bench, const std::vector<FidelityCase>& presses,
                                              const sensors::SensorProfile& profile,
                                              const contact::ReconstructionOptions& reconstruction,
                                              const FaultyTaxelOptions& options) {
  std::vector<int> taxels = options.taxels;
  if (taxels.empty())
    for (int k = 0; k < profile.taxel_count; ++k) taxels.push_back(k);
  std::vector<FaultyTaxelRow> rows;
  for (size_t p = 0; p < presses.size(); ++p) {
    const FidelityCase& press = presses[p];
    FidelityMaps maps;
    const FidelityRow healthy = bench.Run(JudgedByTaxelHealth(press, profile), &maps);
    const bool healthy_within = healthy.truth_valid && WithinTargets(healthy.recon_error);
    const size_t quiet = QuietScans(press);
    const int healthy_driving =
        Reconstruct(JudgedByTaxelHealth(press, profile), quiet, quiet, 0, profile, reconstruction).quiet_driving;
    std::vector<FaultyTaxelRow> press_rows;
    for (TaxelFaultKind kind : options.kinds)
      for (int taxel : taxels) {
        FaultyTaxelRow r;
        r.press = press.name;
        r.taxel = taxel;
        r.kind = kind;
        r.healthy_within = healthy_within;
        const FidelityCase judged =
            JudgedByTaxelHealth(WithFaultyTaxel(press, profile, taxel, kind, options.stuck_N), profile, &r.health);
        r.row = bench.Run(judged, &maps);
        r.row.name = press.name;
        r.within = r.row.truth_valid && WithinTargets(r.row.recon_error);
        const size_t peak = PeakScan(judged, profile);
        const sensors::Scan& at_peak = judged.scans[peak];
        for (size_t k = 0; k < at_peak.flags.size(); ++k) r.left_out_at_peak += (at_peak.flags[k] & sensors::kTaxelMasked) != 0;
        r.taxel_left_out_at_peak = (at_peak.flags[size_t(taxel)] & sensors::kTaxelMasked) != 0;
        r.quiet_scans = int(quiet);
        const ReconstructedPress recon = Reconstruct(judged, quiet, peak, taxel, profile, reconstruction);
        r.quiet_scans_driving = recon.quiet_driving;
        r.fit_use_at_peak = recon.use_at_last;
        r.healthy_quiet_scans_driving = healthy_driving;
        press_rows.push_back(std::move(r));
      }
    rows.insert(rows.end(), press_rows.begin(), press_rows.end());
    if (options.progress) options.progress(p + 1, presses.size(), press_rows);
  }
  return rows;
}

FaultyTaxelTally Tally(const std::vector<FaultyTaxelRow>& rows, TaxelFaultKind kind) {
  FaultyTaxelTally t;
  for (const FaultyTaxelRow& r : rows) {
    if (r.kind != kind) continue;
    ++t.rows;
    t.quiet_scans += r.quiet_scans;
    t.quiet_scans_driving += r.quiet_scans_driving;
    t.healthy_quiet_scans_driving += r.healthy_quiet_scans_driving;
    t.rows_driving_before_contact += r.quiet_scans_driving > 0;
    if (!r.row.truth_valid) continue;  // nothing to score against (as the healthy benchmark)
    ++t.scored;
    t.within += r.within;
    t.healthy_within += r.healthy_within;
  }
  return t;
}

void WriteFaultyTaxelCsv(const std::string& path, const std::vector<FaultyTaxelRow>& rows) {
  std::ofstream csv(path);
  csv << "case,taxel,fault,shape,force_N,truth_valid,healthy_within_targets,recon_ok,recon_shape,recon_radius_mm,"
         "recon_force_N,recon_rms_sigma,truth_max_sed_Pa,recon_max_sed_Pa,recon_peak_ratio,recon_rel_l2,"
         "recon_peak_offset_mm,recon_command_rel_l2,within_targets,taxel_left_out_at_peak,left_out_at_peak,fit_taxel_use_at_peak,"
         "quiet_scans,quiet_scans_driving,healthy_quiet_scans_driving,recon_press,taxel_health\n";
  for (const FaultyTaxelRow& r : rows) {
    const FidelityRow& f = r.row;
    const auto& e = f.recon_object;
    const char* recon_shape = f.recon_two_contacts ? "two_spheres" : sensors::ContactShapeName(e.shape);
    char line[1024];
    std::snprintf(line, sizeof line, "%s,%d,%s,%s,%g,%d,%d,%d,%s,%g,%g,%g,%g,%g,%g,%g,%g,%g,%d,%d,%d,%d,%d,%d,%d,\"%s\",\"%s\"\n",
                  r.press.c_str(), r.taxel, ToString(r.kind),
                  f.truth_is_primitive ? sensors::ContactShapeName(f.truth_object.shape) : "other",
                  f.truth_object.normal_force_N, f.truth_valid ? 1 : 0, r.healthy_within ? 1 : 0, f.recon_ok ? 1 : 0,
                  recon_shape, e.radius_mm, e.normal_force_N + (f.recon_two_contacts ? f.recon_second.normal_force_N : 0.0),
                  f.recon_rms_sigma, f.truth_max_sed_Pa, f.recon_max_sed_Pa, f.recon_error.peak_ratio,
                  f.recon_error.rel_l2, f.recon_error.peak_offset_mm, f.recon_error.command_rel_l2, r.within ? 1 : 0,
                  r.taxel_left_out_at_peak ? 1 : 0, r.left_out_at_peak, int(r.fit_use_at_peak), r.quiet_scans, r.quiet_scans_driving, r.healthy_quiet_scans_driving,
                  f.recon_press.c_str(), r.health.c_str());
    csv << line;
  }
}

void PrintFaultyTaxelSummary(const std::vector<FaultyTaxelRow>& rows, int worst) {
  const FidelityTargets t;
  std::printf("faulty taxels, within all three targets (peak ratio %.2f-%.2f, rel. L2 <= %.2f, peak offset <= %.1f mm):\n",
              t.min_peak_ratio, t.max_peak_ratio, t.max_rel_l2, t.max_peak_offset_mm);
  for (TaxelFaultKind kind : {TaxelFaultKind::kDead, TaxelFaultKind::kStuckHigh}) {
    const FaultyTaxelTally c = Tally(rows, kind);
    if (c.rows == 0) continue;
    std::printf("  one taxel %-5s: %d of %d scored (%.1f %%; the same presses healthy: %d of %d)%s; before the "
                "contact: %d of %d scans drive the display, in %d presses (healthy: %d scans)\n",
                ToString(kind), c.within, c.scored, 100.0 * c.WithinShare(), c.healthy_within, c.scored,
                kind == TaxelFaultKind::kDead ? (c.WithinShare() >= 0.9 ? " [target >= 90 %: met]" : " [target >= 90 %: missed]") : "",
                c.quiet_scans_driving, c.quiet_scans, c.rows_driving_before_contact, c.healthy_quiet_scans_driving);
  }
  std::vector<const FaultyTaxelRow*> sorted;
  for (const FaultyTaxelRow& r : rows)
    if (r.row.truth_valid) sorted.push_back(&r);
  std::stable_sort(sorted.begin(), sorted.end(), [](const auto* a, const auto* b) { return Badness(*a) > Badness(*b); });
  if (sorted.size() > size_t(worst)) sorted.resize(size_t(worst));
  if (sorted.empty()) return;
  std::printf("worst %zu:\n  %-10s %5s %-5s %6s | %6s %6s %6s | %-6s %s\n", sorted.size(), "case", "taxel", "fault",
              "F_N", "peak", "L2", "off", "within", "leader press (recon) / taxel left out at the peak (health, fit)");
  for (const FaultyTaxelRow* r : sorted) {
    const MethodError& e = r->row.recon_error;
    std::printf("  %-10s %5d %-5s %6.3f | %6.2f %6.2f %6.2f | %-6s %s / %s, %s\n", r->press.c_str(), r->taxel,
                ToString(r->kind), r->row.truth_object.normal_force_N, e.peak_ratio, e.rel_l2, e.peak_offset_mm,
                r->within ? "yes" : "no", r->row.recon_press.c_str(), r->taxel_left_out_at_peak ? "yes" : "no",
                r->fit_use_at_peak == contact::TaxelUse::kLoneMisfit ? "yes" : "no");
  }
}

}  // namespace sedbridge::fidelity
