// sedbridge fidelity: the SED the bridge delivers against the SED of the same object pressed
// on the leader's fingertip model (fidelity/fidelity_benchmark.h), over recorded presses.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "app/arg_parser.h"
#include "app/command.h"
#include "app/display_fidelity_report.h"
#include "app/plot_runner.h"
#include "bridge/bridge_config.h"
#include "bridge/fingers.h"
#include "common/resource_path.h"
#include "display/display_profile.h"
#include "fidelity/faulty_taxel_fidelity.h"
#include "fidelity/fidelity_benchmark.h"
#include "fidelity/truth_resolution.h"
#include "sensors/calibration_press.h"

namespace sedbridge::app {
namespace {

using namespace sedbridge::bridge;
using namespace sedbridge::fidelity;

// `--through-press`: every stride-th scan of each press scored against its truth, the
// reconstructed contact only (the pressure map misses everywhere: docs/bridge-fidelity.md).
void ScoreThroughPresses(FidelityBenchmark& bench, const std::vector<FidelityCase>& presses, int stride,
                         const std::string& out) {
  std::ofstream csv(out + "/fidelity_scans.csv");
  csv << "case,scan,t_s,force_N,truth_valid,recon_ok,recon_radius_mm,truth_max_sed_Pa,recon_max_sed_Pa,"
         "recon_peak_ratio,recon_rel_l2,recon_peak_offset_mm,recon_peak_region_offset_mm,recon_within_targets\n";
  std::printf("through the presses (every %d%s scan from a quarter of the peak force):\n%-16s %6s %7s %9s %9s %9s %9s\n",
              stride, stride == 1 ? "" : "th", "case", "scans", "within", "L2 med", "L2 max", "peak max", "step max");
  std::vector<double> all_l2, all_steps;
  int all_scored = 0, all_within = 0;
  for (const FidelityCase& press : presses) {
    const auto scores = bench.RunThroughPress(press, stride);
    std::vector<double> l2;
    int within = 0;
    double worst_peak = 1;
    for (const auto& s : scores) {
      const bool scored = s.truth_valid && s.recon_ok;
      const bool hit = scored && WithinTargets(s.recon_error);
      char line[512];
      std::snprintf(line, sizeof line, "%s,%zu,%g,%g,%d,%d,%g,%g,%g,%g,%g,%g,%g,%d\n", press.name.c_str(), s.scan, s.t_s,
                    s.force_N, s.truth_valid ? 1 : 0, s.recon_ok ? 1 : 0, s.recon_radius_mm, s.truth_max_sed_Pa,
                    s.recon_max_sed_Pa, s.recon_error.peak_ratio, s.recon_error.rel_l2, s.recon_error.peak_offset_mm,
                    s.recon_error.peak_region_offset_mm, hit ? 1 : 0);
      csv << line;
      if (!s.truth_valid) continue;  // nothing to score against
      l2.push_back(scored ? s.recon_error.rel_l2 : 1.0);  // a fallback scan counts as a miss
      within += hit;
      if (scored && std::abs(std::log(s.recon_error.peak_ratio)) > std::abs(std::log(worst_peak)))
        worst_peak = s.recon_error.peak_ratio;
    }
    if (l2.empty()) continue;
    const std::vector<double> steps = PeakRatioSteps(scores);
    all_steps.insert(all_steps.end(), steps.begin(), steps.end());
    all_l2.insert(all_l2.end(), l2.begin(), l2.end());
    all_scored += int(l2.size());
    all_within += within;
    std::sort(l2.begin(), l2.end());
    std::printf("%-16s %6zu %7d %9.3f %9.3f %9.2f %9.3f\n", press.name.c_str(), l2.size(), within, l2[l2.size() / 2],
                l2.back(), worst_peak, steps.empty() ? 0.0 : *std::max_element(steps.begin(), steps.end()));
  }
  std::sort(all_l2.begin(), all_l2.end());
  if (!all_l2.empty())
    std::printf("through the presses: %d of %d scans within all three targets; L2 median %.3f, p90 %.3f\n", all_within,
                all_scored, all_l2[all_l2.size() / 2], all_l2[size_t(0.9 * double(all_l2.size() - 1))]);
  // Steadiness beside accuracy: how much the delivered / true peak ratio moves between
  // neighbouring scored scans (docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s20).
  std::sort(all_steps.begin(), all_steps.end());
  if (!all_steps.empty()) {
    auto at = [&](double q) { return all_steps[size_t(q * double(all_steps.size() - 1))]; };
    const auto above = all_steps.end() - std::upper_bound(all_steps.begin(), all_steps.end(), 0.1);
    std::printf("steadiness: |log| of the delivered / true peak SED ratio's step between neighbouring scored scans: "
                "median %.4f, p99 %.3f, max %.3f; %td of %zu steps above 0.1\n",
                at(0.5), at(0.99), all_steps.back(), above, all_steps.size());
  }
  std::printf("wrote %s/fidelity_scans.csv\n", out.c_str());
}

// `--faulty-taxels`: the faulty-taxel set instead of the table, with a progress line per press.
int RunFaultyTaxels(FidelityBenchmark& bench, const std::vector<FidelityCase>& presses,
                    const sensors::SensorProfile& profile, const BridgeConfig& config, const std::string& out) {
  FaultyTaxelOptions options;
  std::printf("faulty taxels: %zu presses x %d taxels x dead, stuck high (%.1f N) ...\n", presses.size(),
              profile.taxel_count, options.stuck_N);
  const auto start = std::chrono::steady_clock::now();
  options.progress = [&](size_t done, size_t all, const std::vector<FaultyTaxelRow>& rows) {
    int within = 0;
    for (const FaultyTaxelRow& r : rows) within += r.within;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("[%zu/%zu] %-10s %2d of %2zu within the targets (%s) %6.1f s\n", done, all,
                rows.empty() ? "" : rows[0].press.c_str(), within, rows.size(),
                rows.empty() || !rows[0].row.truth_valid ? "no valid truth: not scored" : "scored", s);
    std::fflush(stdout);
  };
  const std::vector<FaultyTaxelRow> rows =
      RunFaultyTaxelSet(bench, presses, profile, ReconstructionOptionsOf(config), options);
  WriteFaultyTaxelCsv(out + "/faulty_taxels.csv", rows);
  PrintFaultyTaxelSummary(rows);
  std::printf("wrote %s/faulty_taxels.csv\n", out.c_str());
  return 0;
}

// --truth-resolution: the rig's light presses (primitives at most --light-below at their
// hold) and each light object at 1 N too, pressed at sub-node shifts on each model, with node
// and with face contact (fidelity/truth_resolution.h).
int RunTruthResolution(const ArgParser& args, const sensors::SensorProfile& profile, const BridgeConfig& config,
                       const std::string& out) {
  std::vector<std::string> models;
  std::stringstream list(args.Get("truth-resolution"));
  for (std::string m; std::getline(list, m, ',');)
    if (!m.empty()) models.push_back(m);
  const double step_mm = args.GetDouble("shift-step");
  const double light_N = args.GetDouble("light-below");
  if (models.empty() || !(step_mm > 0 && step_mm <= 2) || !(light_N > 0))
    throw UsageError("--truth-resolution MODELS (comma-separated), --shift-step in (0, 2] mm, --light-below > 0 N");
  constexpr double kControl_N = 1.0;
  const std::vector<Eigen::Vector2d> shifts = ShiftGrid(step_mm, 3);
  struct Object {
    std::string label;
    sensors::ContactPrimitive primitive;
    double force_N;
  };
  std::vector<Object> objects;
  for (const sensors::CalibrationPress& p : sensors::LoadCalibrationPresses(config::ResolveResource(args.Get("cases")), profile)) {
    if (!p.is_primitive() || p.object.shape == sensors::ContactShape::kFlat || !(p.object.normal_force_N <= light_N)) continue;
    char label[96];
    std::snprintf(label, sizeof label, "%s %s R%g", p.name.substr(0, p.name.find('.')).c_str(),
                  sensors::ContactShapeName(p.object.shape), p.object.radius_mm);
    sensors::ContactPrimitive normal_only = p.object;
    normal_only.shear_x_N = normal_only.shear_y_N = 0;
    objects.push_back({label, normal_only, p.object.normal_force_N});
    objects.push_back({label, normal_only, kControl_N});
  }
  std::printf("truth resolution: %zu light presses of the rig (<= %g N) and each at %g N, %zu shifts %g mm apart, "
              "models %s, node and face contact\n",
              objects.size() / 2, light_N, kControl_N, shifts.size(), step_mm, args.Get("truth-resolution").c_str());
  std::printf("%-26s %7s %-8s %-5s | %7s %11s %14s %13s\n", "object", "F_N", "model", "cont.", "reached",
              "peak_med_Pa", "peak_min/max", "sum_min/max");
  // Each model and contact loaded once (index: model * 2 + face).
  std::vector<std::unique_ptr<ShiftedTruthLeader>> leaders(2 * models.size());
  auto leader = [&](size_t model, bool face) -> ShiftedTruthLeader& {
    std::unique_ptr<ShiftedTruthLeader>& l = leaders[2 * model + (face ? 1 : 0)];
    if (!l) l = std::make_unique<ShiftedTruthLeader>(models[model], face, config.compliance_cache_dir);
    return *l;
  };
  std::vector<TruthShiftRow> all;
  for (const Object& o : objects)
    for (size_t m = 0; m < models.size(); ++m)
      for (const bool face : {false, true}) {
        const std::string& model = models[m];
        const std::vector<TruthShiftRow> rows = leader(m, face).PressAtShifts(o.label, o.primitive, o.force_N, shifts);
        const TruthSpread s = SpreadOf(rows);
        std::printf("%-26s %7.3g %-8s %-5s | %3d of %d %11.0f %14.2f %13.2f\n", o.label.c_str(), o.force_N,
                    model.c_str(), face ? "face" : "node", s.reached, s.shifts, s.peak_median_Pa, s.peak_min_over_max,
                    s.sum_min_over_max);
        std::fflush(stdout);
        all.insert(all.end(), rows.begin(), rows.end());
      }
  // What the sensor's noise leaves open about the same objects' radii (at their light force),
  // and what that radius range makes of the truth's peak SED on the first model (face
  // contact): the object pressed at R e^-sigma and R e^+sigma (within the plausible radii).
  const contact::ReconstructionOptions reconstruction = ReconstructionOptionsOf(config);
  std::printf("\nthe radius the sensor's noise leaves open (Cramér-Rao bound, 1 sigma of log R with the place, force "
              "and radius unknown, %g counts a reading), and the truth's peak SED on %s (face contact) at R e^-sigma "
              "and R e^+sigma against at R:\n%-26s %7s %10s %17s %10s %17s\n",
              reconstruction.noise_counts, models.front().c_str(), "object", "F_N", "sigma scan", "SED -/+ a scan",
              "sigma 25", "SED -/+ 25 scans");
  for (size_t i = 0; i < objects.size(); i += 2) {
    const Object& o = objects[i];
    const double sigma = LogRadiusSigmaPerScan(profile, o.primitive, reconstruction.noise_counts);
    std::vector<Eigen::Vector2d> here{Eigen::Vector2d::Zero()};
    auto peak_at = [&](double log_factor) {
      sensors::ContactPrimitive p = o.primitive;
      p.radius_mm = std::clamp(p.radius_mm * std::exp(log_factor), reconstruction.min_radius_mm, reconstruction.max_radius_mm);
      const TruthShiftRow r = leader(0, true).PressAtShifts(o.label, p, o.force_N, here).front();
      return r.reached ? r.peak_sed_Pa : std::numeric_limits<double>::quiet_NaN();
    };
    const double at = peak_at(0);
    const double s25 = sigma / 5;
    std::printf("%-26s %7.3g %10.2f %8.2f / %6.2f %10.3f %8.2f / %6.2f\n", o.label.c_str(), o.force_N, sigma,
                peak_at(-sigma) / at, peak_at(sigma) / at, s25, peak_at(-s25) / at, peak_at(s25) / at);
    std::fflush(stdout);
  }
  WriteTruthShiftCsv(out + "/truth_resolution.csv", all);
  std::printf("wrote %s/truth_resolution.csv\n", out.c_str());
  return 0;
}

// The options of `sedbridge fidelity`.
void AddFidelityOptions(ArgParser& args) {
  args.Option("cases", "JSON", "presses to run", "config/sensors/rig_uskin_4x4/cases.json")
      .Option("config", "BRIDGE.yaml",
              "the bridge judged: its fe.contact_tolerance, fe.face_contact, fe.two_contacts, fe.finite_rods, fe.radius_tracking, "
              "fe.compliance_cache, registration, traction and conditioning",
              "config/bridge/default.yaml")
      .Option("profile", "PROFILE", "sensor profile of the logs (needs a forward_model)", "uskin_4x4")
      .Option("model", "MODEL", "leader fingertip model (default: the config's fe.model)")
      .Option("display", "PROFILE", "display profile for the command metric", "suction_4x4")
      .Option("out", "DIR", "output folder", "out/fidelity")
      .Option("cache-dir", "DIR", "compliance precompute cache (default: the config's fe.compliance_cache)")
      .Flag("synthetic", "run the synthetic set instead (simulated sensor: shapes the rig did not press)")
      .Option("pad", "MODEL",
              "the synthetic set's simulated pad: kernel (Winkler pressure through the calibrated kernels), "
              "halfspace (an elastic half-space's pressure, Hertz's law, through the same kernels) or layer (the "
              "rig's elastomer as a 2.5 mm layer on a rigid base, fitted to the rig presses: fit-sensor --evaluate-pad)",
              "layer")
      .Option("random", "N", "--synthetic: N rig-like presses drawn at random instead of the fixed set", "0")
      .Option("random-ranges", "RANGES",
              "--random's draws: rig (sizes, places and depths like the rig's presses) or wide (past them: spheres "
              "1.5-20 mm within 7 mm of the centre, rods 0.4-4 mm, forces from under 0.1 N to several N)",
              "rig")
      .Option("random-faces", "K",
              "--synthetic: also K flat faces drawn at random after --random's presses (rectangular punches 1.5-6 mm "
              "a side, round ones of 1-3.5 mm radius and bars 5-10 mm long, in turn; their own stream, so --random's "
              "rows stay as they are)",
              "0")
      .Flag("rig-on-pad",
            "the presses of --cases re-made on the simulated sensor with --pad (each object at its place, pressed "
            "to its hold force): how far the simulated pad, and so --random's sets, stands in for the recorded sensor")
      .Option("seed", "S", "--synthetic: seed of the noise (and of --random's draws)", "1")
      .Option("through-press", "STRIDE",
              "also score every STRIDE-th scan of each press from a quarter of its peak force on (ramp, hold, "
              "release), not only the peak: fidelity_scans.csv, a summary with the delivered / true peak ratio's steadiness "
              "between scored scans, and fidelity_scans.png (0: off)",
              "0")
      .Option("display-fidelity", "DISPLAYS",
              "also what displays deliver (comma-separated profiles, e.g. pin_6x4,pin_8x8): at the scored scan the "
              "bridge's SED is rendered to commands by --rendering, the commands (clipped to the profile's limits) "
              "pressed on the leader by full contact and that SED scored against the truth and against the SED asked "
              "for: display_fidelity.csv and a table. Each display's precompute is n + 1 contact solves (n actuators); "
              "a display kind with no load on the leader yet is listed, not rendered (off when not given)")
      .Option("rendering", "LIST",
              "--display-fidelity: curve (the profile's mapping curve, as shipped), inverse (the inverse renderer) or "
              "both, comma-separated",
              "curve,inverse")
      .Option("fit-reduction", "SHARE",
              "--display-fidelity: the inverse renderer's fit on the influence reduced per Merkel vertex, leaving out "
              "at most SHARE of the commands' strain energy at any vertex (pins; 0: element by element)",
              "0.01")
      .Flag("faulty-taxels",
            "instead of the table: every press with each single taxel dead and with each single taxel stuck high "
            "(from the first scan), through taxel health, scored at the peak: faulty_taxels.csv and a summary "
            "(src/fidelity/faulty_taxel_fidelity.h)")
      .Flag("node-contact", "press on the leader's skin nodes only (bridge fe.face_contact: false), not its faces too")
      .Flag("beyond-primitives",
            "--synthetic: the presses no contact primitive holds instead (a grating, a cross, three spheres, a tilted "
            "block), for the fallbacks")
      .Option("truth-resolution", "MODELS",
              "instead of the table: how well each leader model (comma-separated, e.g. B,B_fine) resolves the truth "
              "of a light touch: the rig's light presses (--light-below) and the same objects at 1 N, each pressed at "
              "3 x 3 shifts --shift-step apart with node and with face contact; the peak and summed Merkel SED's "
              "min / max over the shifts (1: resolved): truth_resolution.csv and a table")
      .Option("shift-step", "MM", "--truth-resolution: the shifts' spacing [mm]", "0.25")
      .Option("light-below", "N", "--truth-resolution: the rig's presses at most this hold force are light", "0.3")
      .Flag("no-plots", "skip the PNG plots");
}

// The presses --cases, --synthetic (with --random) or --rig-on-pad ask for.
std::vector<FidelityCase> SelectPresses(const ArgParser& args, const sensors::SensorProfile& profile) {
  std::vector<FidelityCase> presses;
  if (args.GetFlag("synthetic") || args.GetFlag("rig-on-pad")) {
    const auto pad = config::ParseEnum<sensors::PadMechanics>(args.Get("pad"), "--pad model");
    if (pad == sensors::PadMechanics::kWinkler)
      throw std::invalid_argument("--pad: the synthetic set needs the kernels (kernel, halfspace or layer), not winkler");
    std::printf("fidelity: simulating %s (pad model %s) ...\n",
                args.GetFlag("rig-on-pad") ? "the rig's presses on the simulated sensor" : "the synthetic set",
                args.Get("pad").c_str());
    const long random = args.GetInt("random");
    if (random < 0 || random > 1000) throw UsageError("--random must be in 0..1000");
    const auto seed = static_cast<uint64_t>(args.GetInt("seed"));
    if (args.GetFlag("rig-on-pad")) {
      if (random > 0 || args.GetInt("random-faces") > 0)
        throw UsageError("--rig-on-pad and --random choose different presses: give one");
      if (args.Has("random-ranges"))
        throw UsageError("--random-ranges draws --random's presses: give --random N, not --rig-on-pad");
      presses = CalibrationPressesOnSimulatedPad(
          sensors::LoadCalibrationPresses(config::ResolveResource(args.Get("cases")), profile), profile, seed, pad);
    } else {
      if (random == 0 && args.Has("random-ranges")) throw UsageError("--random-ranges needs --random N");
      const long faces = args.GetInt("random-faces");
      if (faces < 0 || faces > 1000) throw UsageError("--random-faces must be in 0..1000");
      const auto ranges = config::ParseEnum<RandomRanges>(args.Get("random-ranges"), "--random-ranges");
      if (args.GetFlag("beyond-primitives")) {
        if (random > 0 || faces > 0)
          throw UsageError("--beyond-primitives and --random / --random-faces choose different presses: give one");
        presses = BeyondPrimitiveFidelityCases(profile, seed, pad);
      } else {
        presses = SyntheticFidelityCases(profile, seed, pad, static_cast<int>(random), ranges, static_cast<int>(faces));
      }
    }
  } else {
    for (const auto& p : sensors::LoadCalibrationPresses(config::ResolveResource(args.Get("cases")), profile))
      presses.push_back(FromCalibrationPress(p));
  }
  return presses;
}

// The scored cases within all three targets, per method (by argmax, by peak region) and per
// kind of object; the cases without a valid truth apart.
struct TargetTally {
  int scored = 0, map_hits = 0, recon_hits = 0, recon_region_hits = 0;
  std::vector<std::string> no_truth;
  // Per kind of object, in order of first appearance: scored, reconstructed within.
  std::vector<std::pair<std::string, std::pair<int, int>>> by_kind;

  void Add(const FidelityRow& r) {
    // Without a valid truth nothing is scored (two near-zero maps would agree).
    if (!r.truth_valid) {
      no_truth.push_back(r.name + " (" + r.truth_press + ")");
      return;
    }
    const bool recon_within = WithinTargets(r.recon_error);
    ++scored;
    map_hits += WithinTargets(r.map_error);
    recon_hits += recon_within;
    recon_region_hits += WithinTargets(r.recon_error, {}, true);
    const std::string kind = ObjectKind(r);
    auto it = std::find_if(by_kind.begin(), by_kind.end(), [&](const auto& k) { return k.first == kind; });
    if (it == by_kind.end()) it = by_kind.insert(by_kind.end(), {kind, {0, 0}});
    ++it->second.first;
    it->second.second += recon_within;
  }

  void Print() const {
    const FidelityTargets t;
    std::printf("within all three targets (peak ratio %.2f-%.2f, rel. L2 <= %.2f, peak offset <= %.1f mm), of %d "
                "scored cases: reconstructed contact %d (%d by peak region), pressure map %d\n",
                t.min_peak_ratio, t.max_peak_ratio, t.max_rel_l2, t.max_peak_offset_mm, scored, recon_hits,
                recon_region_hits, map_hits);
    if (!by_kind.empty()) {
      std::printf("reconstructed contact by object:");
      for (size_t k = 0; k < by_kind.size(); ++k)
        std::printf("%s %s %d of %d", k ? "," : "", by_kind[k].first.c_str(), by_kind[k].second.second,
                    by_kind[k].second.first);
      std::printf("\n");
    }
    if (!no_truth.empty()) {
      std::printf("not scored, %zu: the object does not reach the measured force on the leader's pad:",
                  no_truth.size());
      for (const auto& n : no_truth) std::printf("\n  %s", n.c_str());
      std::printf("\n");
    }
  }
};

// One case: its line on stdout, its row of fidelity.csv and its Merkel maps in maps/NAME.csv.
void ReportCase(const FidelityRow& r, const FidelityMaps& maps, std::ofstream& csv, const std::string& out) {
  const bool map_within = r.truth_valid && WithinTargets(r.map_error);
  const bool recon_within = r.truth_valid && WithinTargets(r.recon_error);
  const auto& t = r.truth_object;
  const auto& e = r.recon_object;
  const auto& e2 = r.recon_second;
  const char* recon_shape = r.recon_two_contacts ? "two_spheres" : sensors::ContactShapeName(e.shape);
  const double recon_force_N = e.normal_force_N + (r.recon_two_contacts ? e2.normal_force_N : 0.0);
  std::printf("%-16s %-8s %6.3f | %-8s %6.2f %5.2f %6.3f | map: %5.2f %5.2f %5.2f | recon: %5.2f %5.2f %5.2f%s\n",
              r.name.c_str(), r.truth_is_primitive ? sensors::ContactShapeName(t.shape) : "other", t.normal_force_N,
              recon_shape, e.radius_mm, std::hypot(e.x_mm - t.x_mm, e.y_mm - t.y_mm),
              recon_force_N, r.map_error.peak_ratio, r.map_error.rel_l2, r.map_error.peak_offset_mm,
              r.recon_error.peak_ratio, r.recon_error.rel_l2, r.recon_error.peak_offset_mm,
              !r.truth_valid ? "  (no valid truth: not scored)" : r.recon_ok ? "" : "  (fallback)");
  std::fflush(stdout);
  char line[2048];
  std::snprintf(line, sizeof line,
                "%s,\"%s\",%s,%g,%g,%g,%g,%g,%d,%s,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%s,%s,%g,%g,%d,%d,%d,%g,%g,%g,%g,%g,%d,%d,%g\n",
                r.name.c_str(), r.label.c_str(), r.truth_is_primitive ? sensors::ContactShapeName(t.shape) : "other", t.x_mm, t.y_mm, t.radius_mm, t.yaw_deg,
                t.normal_force_N, r.recon_ok ? 1 : 0, recon_shape, e.x_mm, e.y_mm,
                e.radius_mm, e.yaw_deg, recon_force_N, e.shear_x_N, e.shear_y_N, r.recon_rms_sigma,
                r.truth_max_sed_Pa, r.map_max_sed_Pa, r.recon_max_sed_Pa, r.map_error.peak_ratio,
                r.map_error.rel_l2, r.map_error.peak_offset_mm, r.map_error.command_rel_l2,
                r.recon_error.peak_ratio, r.recon_error.rel_l2, r.recon_error.peak_offset_mm,
                r.recon_error.command_rel_l2, r.recon_median_us, r.recon_max_us, r.truth_press.c_str(),
                r.recon_press.c_str(), r.map_error.peak_region_offset_mm, r.recon_error.peak_region_offset_mm,
                r.truth_valid ? 1 : 0, map_within ? 1 : 0, recon_within ? 1 : 0, e2.x_mm, e2.y_mm, e2.radius_mm,
                e2.normal_force_N, e.shape == sensors::ContactShape::kPunch ? 2 * e.half_size_mm[0] : e.length_mm,
                r.recon_inadequate ? 1 : 0, r.recon_inadequate_scans,
                e.shape == sensors::ContactShape::kPunch ? 2 * e.half_size_mm[1] : 0.0);
  csv << line;
  std::ofstream m(out + "/maps/" + r.name + ".csv");
  m << "x_mm,y_mm,z_mm,truth_sed_Pa,map_sed_Pa,recon_sed_Pa\n";
  for (Eigen::Index i = 0; i < maps.truth.size(); ++i)
    m << maps.merkel_pad_mm(0, i) << ',' << maps.merkel_pad_mm(1, i) << ',' << maps.merkel_pad_mm(2, i) << ','
      << maps.truth[i] << ',' << maps.map[i] << ',' << maps.recon[i] << '\n';
}

// The surface pressure beside the map and the reconstruction, one row per case
// (fidelity_surface.csv), and its tally: what the fallback that assumes no shape delivers.
class SurfaceReport {
 public:
  explicit SurfaceReport(const std::string& out) : csv_(out + "/fidelity_surface.csv") {
    csv_ << "case,kind,truth_valid,recon_ok,recon_inadequate,surface_ok,surface_force_N,force_N,surface_rms_sigma,"
            "surface_cells,surface_us,surface_peak_ratio,surface_rel_l2,surface_peak_offset_mm,"
            "surface_peak_region_offset_mm,surface_command_rel_l2,surface_within_targets,map_peak_ratio,map_rel_l2,"
            "map_within_targets,recon_peak_ratio,recon_rel_l2,recon_within_targets,recon_answered_by_surface\n";
  }
  void Add(const FidelityRow& r) {
    const bool surface_within = r.truth_valid && r.surface_ok && WithinTargets(r.surface_error);
    const bool map_within = r.truth_valid && WithinTargets(r.map_error);
    const bool recon_within = r.truth_valid && WithinTargets(r.recon_error);
    char line[1024];
    std::snprintf(line, sizeof line, "%s,%s,%d,%d,%d,%d,%g,%g,%g,%d,%g,%g,%g,%g,%g,%g,%d,%g,%g,%d,%g,%g,%d,%d\n",
                  r.name.c_str(), ObjectKind(r).c_str(), r.truth_valid, r.recon_ok, r.recon_inadequate, r.surface_ok,
                  r.surface_force_N, r.truth_object.normal_force_N, r.surface_rms_sigma, r.surface_cells, r.surface_us,
                  r.surface_error.peak_ratio, r.surface_error.rel_l2, r.surface_error.peak_offset_mm,
                  r.surface_error.peak_region_offset_mm, r.surface_error.command_rel_l2, surface_within,
                  r.map_error.peak_ratio, r.map_error.rel_l2, map_within, r.recon_error.peak_ratio,
                  r.recon_error.rel_l2, recon_within, r.recon_fallback_surface);
    csv_ << line;
    if (!r.truth_valid) return;
    ++scored_;
    surface_hits_ += surface_within;
    map_hits_ += map_within;
    ratios_.push_back(r.surface_ok ? r.surface_error.peak_ratio : 0.0);
    map_ratios_.push_back(r.map_error.peak_ratio);
    l2_.push_back(r.surface_ok ? r.surface_error.rel_l2 : 1.0);
    map_l2_.push_back(r.map_error.rel_l2);
  }
  void Print(const std::string& out) {
    if (scored_ == 0) return;
    auto median = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      return v[v.size() / 2];
    };
    auto range = [](const std::vector<double>& v) { return std::make_pair(*std::min_element(v.begin(), v.end()), *std::max_element(v.begin(), v.end())); };
    const auto sr = range(ratios_), mr = range(map_ratios_);
    std::printf("surface pressure (the fallback that assumes no shape), of %d scored cases: within all three targets %d "
                "(pressure map %d); peak SED ratio median %.2f, range %.2f-%.2f (map %.2f, %.2f-%.2f); rel. L2 median "
                "%.2f (map %.2f)\nwrote %s/fidelity_surface.csv\n",
                scored_, surface_hits_, map_hits_, median(ratios_), sr.first, sr.second, median(map_ratios_), mr.first,
                mr.second, median(l2_), median(map_l2_), out.c_str());
  }

 private:
  std::ofstream csv_;
  int scored_ = 0, surface_hits_ = 0, map_hits_ = 0;
  std::vector<double> ratios_, map_ratios_, l2_, map_l2_;
};

// `--display-fidelity`: the displays' renderings built up front (a wrong name or rendering is
// refused before the benchmark's work); nullptr when not asked for.
std::unique_ptr<DisplayFidelityReport> MakeDisplayReport(const ArgParser& args, const std::string& model,
                                                         const std::string& cache_dir, const std::string& out) {
  const auto displays = args.GetOptional("display-fidelity");
  if (!displays) {
    if (args.Has("rendering")) throw UsageError("--rendering needs --display-fidelity DISPLAYS");
    if (args.Has("fit-reduction")) throw UsageError("--fit-reduction needs --display-fidelity DISPLAYS");
    return nullptr;
  }
  DisplayFidelityOptions options;
  options.cache_dir = cache_dir;
  options.progress = stdout;
  try {
    options.displays = SplitNameList(*displays, "--display-fidelity");
    options.renderings = ParseRenderings(args.Get("rendering"));
    options.fit_reduction = args.GetDouble("fit-reduction");
    if (!(options.fit_reduction >= 0 && options.fit_reduction < 1))
      throw UsageError("--fit-reduction: a share in [0, 1), got " + args.Get("fit-reduction"));
    return std::make_unique<DisplayFidelityReport>(model, std::move(options), out);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

int RunFidelity(int argc, char** argv) {
  ArgParser args("sedbridge fidelity",
                 "Fidelity benchmark: for every recorded press (cases.json + candump logs of the\n"
                 "follower's sensor with known objects and forces) compares, at the scan of peak force,\n"
                 "the Merkel-layer SED of the object pressed directly on the leader's model (truth)\n"
                 "with what the bridge delivers: the pressure-map boundary condition (map) and the\n"
                 "reconstructed contact pressed on the leader's model (recon). Writes fidelity.csv,\n"
                 "one Merkel map CSV per case and side-by-side plots.");
  AddFidelityOptions(args);
  if (!args.Parse(argc, argv)) return 0;
  BridgeConfig config = LoadBridgeConfig(config::ResolveResource(args.Get("config")));
  RequireOneFinger(config, "fidelity");
  if (auto dir = args.GetOptional("cache-dir")) config.compliance_cache_dir = *dir;
  if (args.GetFlag("node-contact")) config.face_contact = false;
  const std::string model = args.GetOptional("model").value_or(config.model);
  const std::string out = args.Get("out");
  if (args.GetInt("through-press") < 0) throw UsageError("--through-press must be 0 (off) or a stride of 1 or more");
  if (args.GetOptional("truth-resolution")) {
    std::filesystem::create_directories(out);
    return RunTruthResolution(args, sensors::LoadNamedSensorProfile(args.Get("profile")), config, out);
  }
  std::filesystem::create_directories(out + "/maps");
  std::unique_ptr<DisplayFidelityReport> display_report = MakeDisplayReport(args, model, config.compliance_cache_dir, out);
  const auto profile = sensors::LoadNamedSensorProfile(args.Get("profile"));
  const std::vector<FidelityCase> presses = SelectPresses(args, profile);
  std::printf("fidelity: %zu presses, model %s, bridge config %s (fe.contact_tolerance %g), building the leader's "
              "compliance ...\n",
              presses.size(), model.c_str(), args.Get("config").c_str(), config.contact_tolerance);
  FidelityBenchmark bench(model, profile, display::LoadNamedDisplayProfile(args.Get("display")), config);
  if (args.GetFlag("faulty-taxels")) return RunFaultyTaxels(bench, presses, profile, config, out);
  std::ofstream csv(out + "/fidelity.csv");
  csv << "case,label,shape,x_mm,y_mm,radius_mm,yaw_deg,force_N,recon_ok,recon_shape,recon_x_mm,recon_y_mm,recon_radius_mm,"
         "recon_yaw_deg,recon_force_N,recon_shear_x_N,recon_shear_y_N,recon_rms_sigma,truth_max_sed_Pa,map_max_sed_Pa,"
         "recon_max_sed_Pa,map_peak_ratio,map_rel_l2,map_peak_offset_mm,map_command_rel_l2,recon_peak_ratio,"
         "recon_rel_l2,recon_peak_offset_mm,recon_command_rel_l2,recon_median_us,recon_max_us,truth_press,recon_press,"
         "map_peak_region_offset_mm,recon_peak_region_offset_mm,truth_valid,map_within_targets,recon_within_targets,"
         "recon2_x_mm,recon2_y_mm,recon2_radius_mm,recon2_force_N,recon_length_mm,recon_inadequate,"
         "recon_inadequate_scans,recon_width_mm\n";
  std::printf("%-16s %-8s %6s | %-8s %6s %5s %6s | map: %5s %5s %5s | recon: %5s %5s %5s\n", "case", "object", "F_N",
              "recon", "R_mm", "dxy", "F_N", "peak", "L2", "off", "peak", "L2", "off");
  TargetTally tally;
  SurfaceReport surface(out);
  for (const auto& press : presses) {
    FidelityMaps maps;
    const FidelityRow r = bench.Run(press, &maps);
    tally.Add(r);
    surface.Add(r);
    ReportCase(r, maps, csv, out);
    if (display_report) display_report->Add(r, maps);
  }
  csv.close();
  tally.Print();
  surface.Print(out);
  if (display_report) display_report->Print();
  std::printf("wrote %s/fidelity.csv and %s/maps/\n", out.c_str(), out.c_str());
  if (const long stride = args.GetInt("through-press"); stride > 0) ScoreThroughPresses(bench, presses, int(stride), out);
  if (!args.GetFlag("no-plots")) RunPlotScript("plot_fidelity.py", {out});
  return 0;
}

}  // namespace

SEDBRIDGE_COMMAND(fidelity, "fidelity", "bridge SED vs the same object pressed on the leader's model", RunFidelity);

}  // namespace sedbridge::app
