#pragma once
// Display fidelity, end to end (`sedbridge fidelity --display-fidelity`): what the display
// delivers to the leader, not only what the bridge asks of it.
//
// Per case, at the benchmark's scored scan (fidelity_benchmark.h), the bridge's Merkel SED
// (the reconstructed contact's, or the pressure map's where the fit fell back: what the
// bridge hands the display stage) is rendered to commands by
//   curve    the profile's per-actuator curve (display::SedToCommandMapping), the product's
//            path today;
//   inverse  the inverse renderer (render::DisplayRendering::Render);
// each command vector, clipped to [0, the profile's per-actuator maximum], is pressed on the
// leader's finger by the full contact (DisplayRendering::Deliver), and the SED it adds is
// scored against the truth (the object pressed on the leader, the benchmark's truth) with
// the benchmark's measures, and against the SED asked for (the renderer's own error).
//
// A display kind without a mechanical load on the leader yet (MakeDisplayOnLeader refuses
// it: suction until its load is built; electrotactile has none) is listed with its status,
// never rendered.

#include <Eigen/Core>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "display/display_profile.h"
#include "fidelity/fidelity_benchmark.h"
#include "render/display_rendering.h"

namespace sedbridge::model {
struct FingertipModel;
}
namespace sedbridge::render {
class DisplayRendering;
}
namespace sedbridge::display {
class SedToCommandMapping;
}

namespace sedbridge::fidelity {

/// How the bridge's SED becomes commands.
enum class DisplayRenderingMethod { kCurve, kInverse };
const char* RenderingName(DisplayRenderingMethod method);

/// "a,b,c" -> names, in order; empty items and repeats refused (std::invalid_argument naming
/// `what`).
std::vector<std::string> SplitNameList(const std::string& list, const std::string& what);
/// "curve,inverse" (either or both) -> methods; anything else refused (std::invalid_argument).
std::vector<DisplayRenderingMethod> ParseRenderings(const std::string& list);

/// One case on one display by one rendering.
struct DisplayFidelityRow {
  std::string case_name, display, rendering;
  /// "ok"; "no valid truth" (delivered vs asked only); "no device load yet" (a display whose
  /// load on the leader is not built: nothing rendered); "does not fit the pad" (footprints
  /// off the leader's pad, render/leader_pad.h: nothing rendered); "no mechanical load"
  /// (electrotactile: nothing to render on the leader); "precompute failed" (its influence
  /// could not be built: nothing rendered); "deliver failed: ..." (contact solve).
  std::string status;
  bool scored = false;          ///< delivered vs truth measured (status "ok")
  int actuators = 0;
  MethodError delivered;        ///< the delivered SED against the truth (command_rel_l2 unused)
  double vs_asked_rel_l2 = 0;   ///< |delivered - asked| / |asked|: the rendering's own error
  double asked_max_sed_Pa = 0, delivered_max_sed_Pa = 0, truth_max_sed_Pa = 0;
  double render_ms = 0;         ///< the SED -> commands step alone (median of repeats, cold start)
  int commands_at_max = 0;      ///< after clipping, at the profile's maximum
  double max_command_share = 0; ///< largest command / its maximum, after clipping (<= 1)
};

struct DisplayFidelityOptions {
  std::vector<std::string> displays;                ///< profile names or paths
  std::vector<DisplayRenderingMethod> renderings = {DisplayRenderingMethod::kCurve, DisplayRenderingMethod::kInverse};
  std::string cache_dir;                            ///< leader compliance cache ("" = none)
  int timing_repeats = 3;                           ///< renders a case is timed over (>= 1)
  /// The inverse renderer's fit reduction (render::DisplayRenderingOptions::fit_reduction).
  double fit_reduction = render::DisplayRenderingOptions{}.fit_reduction;
  std::FILE* progress = nullptr;                    ///< precompute progress lines (nullptr: quiet)
};

class DisplayFidelity {
 public:
  /// Loads every display profile (std::invalid_argument naming an unknown or bad one, before
  /// any precompute) and builds each one's rendering on `model_name` (n + 1 contact solves a
  /// display with n actuators; one with no load on the leader, or whose precompute fails, is
  /// kept, unrendered, with its reason).
  DisplayFidelity(const std::string& model_name, DisplayFidelityOptions options);
  ~DisplayFidelity();

  /// The rows of one benchmark case (`row` and `maps` as FidelityBenchmark::Run answered):
  /// one per display and rendering, in the options' order.
  std::vector<DisplayFidelityRow> Score(const FidelityRow& row, const FidelityMaps& maps);

  struct DisplayInfo {
    std::string name;
    int actuators = 0;
    bool has_load = false;      ///< rendered and delivered on the leader
    /// Why not, when !has_load: "no device load yet" (the kind has no load on the leader:
    /// MakeDisplayOnLeader refuses it), "no mechanical load" (electrotactile), "does not fit the pad" (render::DisplayDoesNotFitPad,
    /// the reason names the profile's file:line:column) or "precompute failed" (a contact solve of the
    /// influence did not converge); the rows carry it as their status.
    std::string no_load_status;
    std::string no_load_reason; ///< the message behind it
    double precompute_s = 0;    ///< the rendering's precompute (leader, preload, influence)
  };
  const std::vector<DisplayInfo>& displays() const { return info_; }

 private:
  struct Display;
  DisplayFidelityOptions options_;
  std::unique_ptr<model::FingertipModel> model_;
  std::vector<std::unique_ptr<Display>> displays_;
  std::vector<DisplayInfo> info_;
};

/// Medians over the scored rows of one display and rendering (the printed table).
struct DisplayFidelitySummary {
  std::string display, rendering, status;  ///< status: "ok" or the rows' common status when none scored
  int rows = 0, scored = 0, within_targets = 0;
  int deliver_failed = 0;   ///< rows whose full-contact press failed (not in the medians)
  double peak_ratio = 0, rel_l2 = 0, peak_offset_mm = 0, vs_asked_rel_l2 = 0, render_ms = 0;
  int commands_at_max = 0;  ///< summed over the scored rows
};
/// One summary per (display, rendering), in order of first appearance in `rows`.
std::vector<DisplayFidelitySummary> SummarizeDisplayFidelity(const std::vector<DisplayFidelityRow>& rows);

}  // namespace sedbridge::fidelity
