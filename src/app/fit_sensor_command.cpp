// sedbridge fit-sensor: calibrates the follower sensor's forward model to indentation-stage
// presses (a cases.json plus candump logs) and prints the `forward_model:` block for the
// sensor profile, with how well each press is reproduced.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "app/arg_parser.h"
#include "app/command.h"
#include "common/resource_path.h"
#include "sensors/calibration_press.h"
#include "sensors/simulated/pad_rig_check.h"
#include "sensors/tactile_model_fit.h"

namespace sedbridge::app {
namespace {

using namespace sedbridge::sensors;

void PrintReport(const std::vector<PressFitReport>& presses) {
  std::printf("%-14s %8s %8s %8s %10s %10s\n", "press", "rms_x", "rms_y", "rms_z", "sum_z_N", "model_z_N");
  for (const auto& p : presses)
    std::printf("%-14s %8.2f %8.2f %8.2f %10.4f %10.4f\n", p.name.c_str(), p.rms_sigma[0], p.rms_sigma[1],
                p.rms_sigma[2], p.measured_sum_z_N, p.predicted_sum_z_N);
}

// The simulated pad beside the forward model, press by press (hold; the pad also on the
// ramp at light load), and the medians.
void PrintPadReport(const std::vector<PressFitReport>& model, const std::vector<PadPressReport>& pad,
                    const std::string& pad_name) {
  std::printf("%-14s %26s   %26s   %26s %9s\n", "", "forward model hold x/y/z", (pad_name + " pad hold x/y/z").c_str(),
              (pad_name + " pad ramp x/y/z").c_str(), "depth_mm");
  std::vector<double> worst_model, worst_pad, worst_ramp;
  auto worst = [](const double* r) { return std::max({r[0], r[1], r[2]}); };
  for (size_t i = 0; i < pad.size(); ++i) {
    const double* m = model[i].rms_sigma;
    const double* p = pad[i].rms_sigma;
    const double* q = pad[i].ramp_rms_sigma;
    worst_model.push_back(worst(m));
    if (!pad[i].reached) {
      std::printf("%-14s %8.2f %8.2f %8.2f   %26s\n", pad[i].name.c_str(), m[0], m[1], m[2], "force not reached");
      continue;
    }
    std::printf("%-14s %8.2f %8.2f %8.2f   %8.2f %8.2f %8.2f   %8.2f %8.2f %8.2f %9.3f\n", pad[i].name.c_str(), m[0],
                m[1], m[2], p[0], p[1], p[2], q[0], q[1], q[2], pad[i].depth_mm);
    worst_pad.push_back(worst(p));
    worst_ramp.push_back(worst(q));
  }
  auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  };
  auto within = [](const std::vector<double>& v) {
    return long(std::count_if(v.begin(), v.end(), [](double x) { return x < 1; }));
  };
  std::printf("worst axis per press, median: forward model %.2f, %s pad %.2f (hold) %.2f (ramp); within 1 sigma on "
              "every axis: %ld, %ld and %ld of %zu\n",
              median(worst_model), pad_name.c_str(), median(worst_pad), median(worst_ramp), within(worst_model),
              within(worst_pad), within(worst_ramp), pad.size());
}

// A fitted rod radius below this ran towards 0: the hold does not resolve it [mm].
constexpr double kUnresolvedRadius_mm = 0.05;

// Each rod's hold read back as a rod, and the log error of the rods the sensor resolves.
void PrintRodRadii(const std::vector<RodRadiusReport>& rods, double min_halfwidth_mm) {
  std::printf("rod radius that best explains each rod's hold (rod_min_halfwidth_mm %g):\n", min_halfwidth_mm);
  std::printf("%-14s %10s %10s %10s %8s\n", "press", "true_mm", "fitted_mm", "log_error", "chi2");
  double sum2 = 0;
  int resolved = 0;
  for (const auto& r : rods) {
    const double e = std::log(r.fitted_radius_mm / r.true_radius_mm);
    if (r.fitted_radius_mm < kUnresolvedRadius_mm)
      std::printf("%-14s %10.2f %10s %10s %8.1f\n", r.name.c_str(), r.true_radius_mm, "< 0.05", "-", r.chi2);
    else
      std::printf("%-14s %10.2f %10.2f %10.3f %8.1f\n", r.name.c_str(), r.true_radius_mm, r.fitted_radius_mm, e,
                  r.chi2);
    // A rod thinner than the band the sensor draws of any line contact is not resolved: its
    // fit runs towards 0 whatever the width; only the thicker ones calibrate the width.
    if (r.true_radius_mm >= 1.0) sum2 += e * e, ++resolved;
  }
  if (resolved) std::printf("RMS log error over the %d rods of radius >= 1 mm: %.3f\n", resolved, std::sqrt(sum2 / resolved));
}

int RunFitSensor(int argc, char** argv) {
  ArgParser args("sedbridge fit-sensor",
                 "Calibrates the follower sensor's forward model (sensors/tactile_forward_model.h:\n"
                 "Hertz contact patches on the pad, spread to the taxels by fitted kernels) to\n"
                 "indentation-stage presses of known objects at known forces, by Levenberg–Marquardt.\n"
                 "Prints, per press, the hold-window RMS error per axis in units of the single-scan\n"
                 "noise (about 1 = reproduced within noise) and the `forward_model:` YAML block.");
  args.Option("cases", "JSON", "cases.json of the presses", "config/sensors/rig_uskin_4x4/cases.json")
      .Option("profile", "PROFILE", "sensor profile the logs were recorded with", "uskin_4x4")
      .Option("noise-counts", "N", "single-scan noise of a raw reading (1 sigma) [counts]", "2")
      .Option("out", "YAML", "also write the forward_model block to this file")
      .Option("hold-out", "LOGS", "comma-separated logs left out of the fit and reported after it (validation)")
      .Flag("evaluate", "only report how well the profile's current forward_model reproduces the presses")
      .Flag("rod-radii", "only report, per rod press, the radius at which the forward model explains its hold best "
                         "(what rod_min_halfwidth_mm calibrates)")
      .Option("rod-min-halfwidth-mm", "MM",
              "use this rod_min_halfwidth_mm instead of the profile's (with --evaluate, --rod-radii or a fit)")
      .Option("evaluate-pad", "MODEL",
              "report how well a simulated pad (kernel, halfspace or layer: sensors/simulated/simulated_sensor.h) "
              "reproduces the presses, each pressed to its hold force (and its ramp at 0.29 of it), beside the "
              "forward model")
      .Option("pad-thickness-mm", "MM", "--evaluate-pad: the layer's (or the kernel pad's Winkler layer's) thickness", "3")
      .Option("pad-poisson", "NU", "--evaluate-pad: the elastomer's Poisson ratio, in [0, 0.5)", "0")
      .Option("pad-youngs-kPa", "E", "--evaluate-pad: the elastomer's Young's modulus (kernel and layer pads)", "300")
      .Epilog("examples:\n"
              "  sedbridge fit-sensor --out fitted.yaml    # then paste into config/sensors/uskin_4x4.yaml\n"
              "  sedbridge fit-sensor --evaluate-pad layer --pad-thickness-mm 2.5 --pad-youngs-kPa 230 --pad-poisson 0.2");
  if (!args.Parse(argc, argv)) return 0;
  const SensorProfile profile = LoadNamedSensorProfile(args.Get("profile"));
  const std::string cases = config::ResolveResource(args.Get("cases"));
  std::printf("loading presses from %s ...\n", cases.c_str());
  std::vector<CalibrationPress> presses;
  // A punch or a pair is no primitive of the forward model (yet): said, not fitted.
  for (CalibrationPress& p : LoadCalibrationPresses(cases, profile))
    if (p.is_primitive())
      presses.push_back(std::move(p));
    else
      std::printf("  %s: a %s, which the forward model has no primitive for: left out\n", p.name.c_str(),
                  config::NameOf(p.shape).c_str());
  std::vector<CalibrationPress> held_out;
  if (auto list = args.GetOptional("hold-out")) {
    const std::string names = "," + *list + ",";
    for (auto it = presses.begin(); it != presses.end();)
      if (names.find("," + it->name + ",") != std::string::npos) {
        held_out.push_back(std::move(*it));
        it = presses.erase(it);
      } else {
        ++it;
      }
    if (held_out.empty()) throw UsageError("--hold-out names no log of " + cases);
  }
  FitOptions options;
  options.noise_counts = args.GetDouble("noise-counts");
  TactileModelParams params = profile.forward_model;  // with --rod-min-halfwidth-mm applied
  if (auto w = args.GetOptional("rod-min-halfwidth-mm")) {
    const double mm = args.GetDouble("rod-min-halfwidth-mm");
    if (!(mm >= 0 && mm <= 5)) throw UsageError("--rod-min-halfwidth-mm must be in [0, 5], got " + *w);
    params.rod_min_halfwidth_mm = mm;
  }
  if (args.GetFlag("rod-radii")) {
    if (!profile.has_forward_model) throw UsageError("profile '" + profile.name + "' has no forward_model");
    PrintRodRadii(FitRodRadii(presses, profile, params, options), std::max(params.rod_min_halfwidth_mm, params.grid_mm));
    return 0;
  }
  if (auto model = args.GetOptional("evaluate-pad")) {
    if (!profile.has_forward_model) throw UsageError("profile '" + profile.name + "' has no forward_model");
    PadModel pad;
    try {
      pad.mechanics = config::ParseEnum<PadMechanics>(*model, "--evaluate-pad");
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    if (pad.mechanics == PadMechanics::kWinkler)
      throw UsageError("--evaluate-pad: winkler does not use the kernels; give kernel, halfspace or layer");
    pad.thickness_m = args.GetDouble("pad-thickness-mm") * 1e-3;
    pad.poisson_ratio = args.GetDouble("pad-poisson");
    pad.youngs_modulus_Pa = args.GetDouble("pad-youngs-kPa") * 1e3;
    if (!(pad.youngs_modulus_Pa > 0)) throw UsageError("--pad-youngs-kPa must be > 0");
    if (!(pad.thickness_m > 0)) throw UsageError("--pad-thickness-mm must be > 0");
    if (!(pad.poisson_ratio >= 0 && pad.poisson_ratio < 0.5)) throw UsageError("--pad-poisson must be in [0, 0.5)");
    PrintPadReport(EvaluateTactileModel(presses, profile, profile.forward_model, options),
                   EvaluatePadOnPresses(presses, profile, pad, options.noise_counts), *model);
    return 0;
  }
  if (args.GetFlag("evaluate")) {
    if (!profile.has_forward_model) throw UsageError("profile '" + profile.name + "' has no forward_model");
    PrintReport(EvaluateTactileModel(presses, profile, params, options));
    return 0;
  }
  std::printf("fitting %d parameters to %zu presses (hold + 2 ramp windows each) ...\n",
              TactileModelParams::kCount, presses.size());
  TactileModelParams initial = profile.has_forward_model ? profile.forward_model : InitialTactileModelParams();
  initial.rod_min_halfwidth_mm = params.rod_min_halfwidth_mm;
  FitOptions fit_options = options;
  fit_options.progress = [](const std::string& line) {
    std::printf("  %s ...\n", line.c_str());
    std::fflush(stdout);
  };
  const FitReport rep = FitTactileModel(presses, profile, initial, fit_options);
  std::printf("%s after %d evaluations; RMS over all residuals %.2f sigma\n", rep.status.c_str(), rep.evaluations,
              rep.rms_sigma_all);
  PrintReport(rep.presses);
  if (!held_out.empty()) {
    std::printf("\nheld out (not fitted):\n");
    PrintReport(EvaluateTactileModel(held_out, profile, rep.params, options));
  }
  const std::string yaml = "forward_model:\n" + TactileModelParamsYaml(rep.params, 2);
  std::printf("\n%s", yaml.c_str());
  if (auto out = args.GetOptional("out")) {
    std::ofstream f(*out);
    if (!(f << yaml)) throw std::runtime_error("cannot write " + *out);
  }
  return 0;
}

}  // namespace

SEDBRIDGE_COMMAND(fit_sensor, "fit-sensor", "calibrate the sensor forward model to indentation-stage presses",
                  RunFitSensor);

}  // namespace sedbridge::app
