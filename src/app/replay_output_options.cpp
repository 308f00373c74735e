#include "app/replay_output_options.h"

#include <cstdio>

#include "app/lcm_url.h"

namespace sedbridge::app {

bridge::ReplayOptions ReadReplayOutputOptions(const ArgParser& args, const bridge::BridgeConfig& config) {
  bridge::ReplayOptions options;
  options.out_dir = args.Get("out");
  const LcmUrlChoice url = ChooseLcmUrl(args.GetOptional("lcm-url"), "memq://", "default");
  options.lcm_url = url.url;
  if (url.source != "default") std::printf("LCM: also publishing on %s (from %s)\n", url.url.c_str(), url.source.c_str());
  options.progress = !args.GetFlag("quiet");
  options.vtu_every = static_cast<int>(args.GetInt("vtu-every"));
  if (options.vtu_every < 0) throw UsageError("--vtu-every must be >= 0");
  return options;
}

std::string SaturationNote(const bridge::ReplayResult& r) {
  if (r.scans_at_ceiling == 0) return "";
  char buf[200];
  std::snprintf(buf, sizeof buf, " (%d/%d actuators at the %g %s ceiling: %s; %lld of %zu scans reached it)",
                r.peak_actuators_at_ceiling, r.display_actuators, r.command_ceiling, r.display_unit.c_str(),
                r.inverse_rendering    ? "the inverse renderer's bound, safety.max"
                : r.ceiling_is_mapping ? "the SED mapping saturates"
                                       : "the safety limiter clips",
                static_cast<long long>(r.scans_at_ceiling), r.rows.size());
  return buf;
}

void PrintDisplayRendering(const bridge::ReplayResult& r) {
  std::printf("%s\n", r.display_rendering.c_str());
  if (r.have_sa1_estimate)
    std::printf("electrotactile: no mechanical load on the finger, no SED to deliver; read against the SA1 rate "
                "ESTIMATE (display/sa1_rate_estimate.h: a saturating function of SED, illustrative parameters, not "
                "fitted): at the peak scan %.0f spikes/s (estimate) at electrode %d, site SED %.1f Pa "
                "(peak_sa1_rate_estimate.csv)\n",
                r.sa1_peak_rate_estimate_Hz, r.sa1_peak_electrode, r.sa1_peak_site_sed_Pa);
  if (!r.inverse_rendering) return;
  std::printf("inverse renderer a scan: wall median %.3f ms, p99 %.3f ms, max %.3f ms; CPU median %.3f ms, p99 %.3f "
              "ms, max %.3f ms (%lld scans, %lld stopped at the iteration limit; SED evaluations a scan median %d, "
              "p99 %d, max %d)\n",
              r.render_ms.p50_ms, r.render_ms.p99_ms, r.render_ms.max_ms, r.render_cpu_ms.p50_ms, r.render_cpu_ms.p99_ms,
              r.render_cpu_ms.max_ms, static_cast<long long>(r.render_ms.count),
              static_cast<long long>(r.render_not_converged), r.render_evaluations_median, r.render_evaluations_p99,
              r.render_evaluations_max);
  if (r.have_display_fidelity)
    std::printf("display fidelity at the peak scan (delivered by the full FE vs the bridge's SED): peak ratio %.3f, "
                "rel L2 %.3f, peak offset %.2f mm\n",
                r.display_fidelity.peak_ratio, r.display_fidelity.rel_l2, r.display_fidelity.peak_offset_mm);
  else
    std::printf("display fidelity at the peak scan: not computed (%s)\n", r.display_fidelity_error.c_str());
}

std::vector<std::string> PlotBridgeArgs(const std::string& out_dir, const bridge::ReplayResult& r) {
  char ceiling[32];
  std::snprintf(ceiling, sizeof ceiling, "%g", r.command_ceiling);
  return {out_dir, r.display_unit, ceiling};
}

}  // namespace sedbridge::app
