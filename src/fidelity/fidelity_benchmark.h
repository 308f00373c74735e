#pragma once
// The fidelity benchmark: what the bridge delivers to the leader against what the leader
// would feel touching the same object (docs/bridge-fidelity.md).
//
// Per case (a recorded press of the follower's sensor with its known object and force):
//   truth   the object pressed on the leader's fingertip model (penalty contact by the
//           compliance method, linear quasi-static, bone fixed), same pad-frame pose, at the
//           true force, tangential load included;
//   map     today's bridge: the peak scan as a pressure-map boundary condition
//           (ReducedLinearFeStep, the default bridge config's conditioning);
//   recon   the contact reconstructed from the scans (ContactReconstructor, warm-started
//           through the press) pressed on the same model at the force it estimates; a scan
//           whose fit falls back uses the map's answer, as the bridge would.
// Metrics at the scan of peak measured force, over the Merkel vertices: peak SED ratio
// (method / truth), relative L2 error, distance between the peak locations (pad-frame x, y),
// and the relative L2 error of the display command (display profile's mapping).

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "bridge/bridge_config.h"
#include "bridge/contact_fe_step.h"
#include "contact/surface_pressure_on_leader.h"
#include "display/display_profile.h"
#include "fidelity/fidelity_case.h"
#include "scene/fingertip_compliance.h"
#include "sensors/surface_pressure_inversion.h"

namespace sedbridge::scene {
class FingertipCompliance;
}
namespace sedbridge::model {
struct FingertipModel;
}
namespace sedbridge::display {
class SedToCommandMapping;
}
namespace sedbridge::bridge {
class FeStep;
class ScanConditioner;
}  // namespace sedbridge::bridge

namespace sedbridge::fidelity {

struct MethodError {
  double peak_ratio = 0;       ///< max SED / max truth SED
  double rel_l2 = 0;           ///< |s - s_truth| / |s_truth| over the Merkel layer
  double peak_offset_mm = 0;   ///< pad-frame x-y distance between the peaks
  /// The same for ridges: the larger of the distances from each field's peak to the other
  /// field's peak region (vertices within 5 % of its maximum). 0 when each peak lies in the
  /// other's region. A rod's SED is a ridge whose maximum moves along it by a vertex
  /// spacing (about 1.5 mm) for a few percent of SED; this one does not.
  double peak_region_offset_mm = 0;
  double command_rel_l2 = 0;   ///< same as rel_l2, on the display command
};

/// Map `s` against `truth` (Merkel vertices, pad-frame positions pad_mm [mm], SED [Pa]): peak
/// ratio, relative L2, peak offset and peak-region offset as the benchmark scores a case;
/// command_rel_l2 is left 0 (no display mapping).
MethodError CompareMerkelMaps(const Eigen::Matrix3Xd& pad_mm, const Eigen::VectorXd& s, const Eigen::VectorXd& truth);

/// The fidelity targets at the peak scan (docs/bridge-fidelity.md#the-measure).
struct FidelityTargets {
  double min_peak_ratio = 0.8, max_peak_ratio = 1.25;
  double max_rel_l2 = 0.25;
  double max_peak_offset_mm = 1.0;
};

/// True when peak ratio, relative L2 and peak offset are all within `targets`. With
/// `by_peak_region`, the offset is MethodError::peak_region_offset_mm (ridges), else the
/// argmax distance.
bool WithinTargets(const MethodError& e, const FidelityTargets& targets = {}, bool by_peak_region = false);

struct FidelityRow {
  std::string name;
  std::string label;                   ///< the true object in words
  bool truth_is_primitive = false;
  sensors::ContactPrimitive truth_object;  ///< at the peak scan's force (load from the case)
  sensors::ContactPrimitive recon_object;  ///< estimate at the peak scan (a pair's first sphere)
  bool recon_two_contacts = false;     ///< the estimate is two spheres
  sensors::ContactPrimitive recon_second;  ///< a pair's second sphere
  bool recon_ok = false;               ///< false: fell back to the map
  double recon_rms_sigma = 0;
  bool recon_inadequate = false;       ///< the peak scan's estimate flagged model_inadequate
  int recon_inadequate_scans = 0;      ///< contact scans up to the peak flagged model_inadequate
  double truth_max_sed_Pa = 0, map_max_sed_Pa = 0, recon_max_sed_Pa = 0;
  std::string truth_press, recon_press;  ///< PressToForce status
  /// False when the truth press did not reach the measured force (the object cannot load
  /// the leader's pad that much, e.g. at its edge): the case has no truth to score against,
  /// and the benchmark lists it apart instead of counting it as a hit or a miss.
  bool truth_valid = false;
  MethodError map_error, recon_error;
  double recon_median_us = 0, recon_max_us = 0;  ///< reconstruction time per scan
  int scans = 0, fallbacks = 0;
  /// The surface pressure at the peak scan (sensors/surface_pressure_inversion.h) pressed on
  /// the leader as a traction field (contact/surface_pressure_on_leader.h): the fallback that
  /// assumes no shape. recon_fallback_surface: the reconstruction's answer at the peak scan
  /// was this one (a fallback, or a flagged fit, where the config asks for it).
  bool surface_ok = false, recon_fallback_surface = false;
  double surface_force_N = 0, surface_rms_sigma = 0, surface_max_sed_Pa = 0, surface_us = 0;
  int surface_cells = 0;
  MethodError surface_error;
};

/// The kind of object a row presses, for per-kind counts: "sphere", "rod", "flat", "stroke"
/// (a sphere dragging the pad with a tangential load above 5 % of its normal load at the
/// peak scan) or "other" (a box edge or corner, two spheres: not a primitive).
std::string ObjectKind(const FidelityRow& row);

/// The three Merkel-layer maps of one case [Pa], model.merkel_nodes order.
struct FidelityMaps {
  Eigen::Matrix3Xd merkel_pad_mm;
  Eigen::VectorXd truth, map, recon;
  Eigen::VectorXd surface;  ///< the surface pressure's SED (FidelityRow::surface_ok; else zero)
};

class FidelityBenchmark {
 public:
  /// @param model_name     leader model ("B")
  /// @param profile        follower sensor profile (with forward_model)
  /// @param display        display profile for the command metric, loaded by the caller
  /// @param cache_dir      compliance precompute cache ("" = none)
  /// @param face_contact   leader presses (truth and reconstructed) with face contact, as
  ///                       the bridge's default (fe.face_contact); false: skin nodes only
  FidelityBenchmark(const std::string& model_name, const sensors::SensorProfile& profile,
                    const display::DisplayProfile& display, const std::string& cache_dir, bool face_contact = true);
  /// The bridge a config describes (`sedbridge fidelity --config`): its compliance cache,
  /// fe.face_contact, fe.contact_tolerance (the reconstructed press; the truth stays at the
  /// method's own tolerance), fe.two_contacts, fe.finite_rods, fe.radius_tracking, registration, traction and
  /// conditioning. Its sensor, display and fe.step are not used (the caller's profile and
  /// display; both bridges are always run).
  FidelityBenchmark(const std::string& model_name, const sensors::SensorProfile& profile,
                    const display::DisplayProfile& display, const bridge::BridgeConfig& config);
  ~FidelityBenchmark();

  FidelityRow Run(const FidelityCase& c, FidelityMaps* maps);

  /// One scan of a press scored as Run scores the peak: the truth pressed at that scan's
  /// force and place, the reconstruction as the live bridge has it at that scan.
  struct ScanScore {
    size_t scan = 0;
    double t_s = 0, force_N = 0;
    bool truth_valid = false, recon_ok = false;
    double truth_max_sed_Pa = 0, recon_max_sed_Pa = 0;
    double recon_radius_mm = 0;
    MethodError recon_error;
  };
  /// The whole press, not only its peak: every `stride`-th scan whose true normal force is
  /// at least `min_force_share` of the press's peak (ramps, hold, release), the reconstructed
  /// contact against the truth. What the leader feels while the press grows and lets go.
  std::vector<ScanScore> RunThroughPress(const FidelityCase& c, int stride = 5, double min_force_share = 0.25);

 private:
  sensors::SensorProfile profile_;
  contact::ReconstructionOptions reconstruction_;
  scene::PressToForceOptions press_;
  std::unique_ptr<model::FingertipModel> model_;
  std::unique_ptr<scene::FingertipCompliance> leader_;
  std::unique_ptr<bridge::FeStep> map_step_;
  std::unique_ptr<bridge::ScanConditioner> conditioner_;
  std::unique_ptr<display::SedToCommandMapping> mapping_;
  std::unique_ptr<sensors::SurfacePressureInversion> surface_;
  std::unique_ptr<scene::FingertipCompliance> surface_leader_;
  std::unique_ptr<contact::SurfacePressureOnLeader> surface_on_leader_;
  bridge::FallbackAnswer fallback_ = bridge::FallbackAnswer::kPressureMap;
};

/// How steadily the delivered SED follows the truth from one scored scan of a press to the
/// next: |log(r_k / r_{k-1})| with r = recon_max_sed_Pa / truth_max_sed_Pa, for each pair of
/// neighbouring scores (in the order given) that are both scored (truth valid, the
/// reconstruction ok, both peaks > 0). A bridge that follows the truth's own growth and
/// decay steps near 0 however fast the press changes; a radius that flickers shows here as
/// the leader feels it. Scores of one press, as RunThroughPress returns them.
std::vector<double> PeakRatioSteps(const std::vector<FidelityBenchmark::ScanScore>& scores);

}  // namespace sedbridge::fidelity
