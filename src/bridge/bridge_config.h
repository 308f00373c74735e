#pragma once
// One bridge YAML (config/bridge/*.yaml): which sensor, which fingertip model and preset,
// where the sensor sits on the pad, how taxels become traction, which display, LCM URL and
// channels, rates. Every key is documented in config/bridge/README.md; the reader is strict
// (unknown keys and wrong types are config::ConfigError naming file:line:column).

#include <optional>
#include <string>
#include <vector>

#include "bridge/pad_registration.h"
#include "bridge/taxel_values.h"
#include "bridge/traction_field.h"
#include "common/enum_names.h"
#include "common/name_value.h"
#include "lcm/lcm_channels.h"
#include "scene/scene_description.h"
#include "sensors/surface_pressure_inversion.h"

namespace sedbridge::bridge {

/// Bounds of `rates.*` [Hz]. The tick drives the display's ramp to zero while no scan
/// arrives: below 50 Hz a ramp would move in steps longer than the limiter's rise interval
/// (25 ms) and a 0.05 s watchdog would be noticed late; above 10 kHz it only burns CPU.
/// BRIDGE_STATUS at 0.1..100 Hz (1e-30 Hz overflowed the period).
inline constexpr double kMinTick_Hz = 50, kMaxTick_Hz = 10000;
inline constexpr double kMinStatus_Hz = 0.1, kMaxStatus_Hz = 100;

/// Which FeStep the bridge builds (bridge config `fe.step`).
enum class FeStepKind {
  kScene,    ///< "scene": SceneFeStep, the scene solved every scan
  kReduced,  ///< "reduced": ReducedLinearFeStep (preset fast only)
  kContact,  ///< "contact": ContactFeStep, reconstructed contact pressed on the model (preset fast only)
};
/// "scene", "reduced", "contact": the one name table (common/enum_names.h).
const config::EnumNames<FeStepKind>& NamesOf(FeStepKind);
/// NameOf through the table.
const char* ToString(FeStepKind kind);
/// The kind named `name` (as in the config); throws std::invalid_argument for others.
FeStepKind FeStepKindFromString(const std::string& name);

/// Where the FE step computes the Merkel SED (bridge config `fe.merkel_region`).
enum class MerkelRegion {
  kLayer,    ///< "layer": every vertex of the Merkel layer (viewers, logs and plots see it all)
  kDisplay,  ///< "display": only the vertices the display profile samples (its sites'
             ///< radius_mm in x-y, inside its z window): the same commands, less work
};
const config::EnumNames<MerkelRegion>& NamesOf(MerkelRegion);
const char* ToString(MerkelRegion region);

/// How fe.step contact's reconstruction tracks an object's radius while it touches (bridge
/// config `fe.radius_tracking`; ReconstructionOptions::radius_track_posterior).
enum class RadiusTracking {
  kSteady,     ///< "steady": each scan's fit stays near the last answer (sigma 0.15 in log R)
  kPosterior,  ///< "posterior" (default): while the contact moves, that width grows by what
               ///< the scans so far left open about the radius (closer on light ramps)
};
const config::EnumNames<RadiusTracking>& NamesOf(RadiusTracking);
const char* ToString(RadiusTracking tracking);

/// What answers a scan of fe.step contact that no contact primitive explains (bridge config
/// `fe.fallback`): a fit that falls back (and a leader press that cannot reach its force),
/// and with kSurfacePressureAndFlagged also a fit flagged model_inadequate.
enum class FallbackAnswer {
  kPressureMap,                ///< "pressure_map" (default): the taxel map (fe.step reduced)
  kSurfacePressure,            ///< "surface_pressure": sensors/surface_pressure_inversion.h on the leader
  kSurfacePressureAndFlagged,  ///< "surface_pressure_and_flagged": that, also for flagged fits
};
/// Inline: the YAML fuzzer links the config readers without the stages.
inline const config::EnumNames<FallbackAnswer>& NamesOf(FallbackAnswer) {
  static const config::EnumNames<FallbackAnswer> names{{FallbackAnswer::kPressureMap, "pressure_map"},
                                                       {FallbackAnswer::kSurfacePressure, "surface_pressure"},
                                                       {FallbackAnswer::kSurfacePressureAndFlagged,
                                                        "surface_pressure_and_flagged"}};
  return names;
}

/// How the display's commands are computed from the Merkel SED (bridge config
/// `display.rendering`; bridge/display_requests.h chooses when the key is absent).
enum class RenderingMethod {
  kInverse,  ///< "inverse": the commands whose SED on the leader's FE finger is closest (src/render)
  kCurve,    ///< "curve": the profile's per-site curve (display/sed_to_command_mapping.h)
};
const config::EnumNames<RenderingMethod>& NamesOf(RenderingMethod);
const char* ToString(RenderingMethod method);

/// One entry of the bridge config's `fingers:` list: what differs between the fingers of a
/// hand (its sensor on its bus, its leader model, its display). A key left out takes the
/// bridge's own (`sensor.profile`, `sensor.interface`, `fe.model`, `display.profile`);
/// everything else (FE, traction, rates, LCM) is the bridge's for every finger.
struct FingerConfig {
  std::string name;  ///< [A-Za-z][A-Za-z0-9_]*, unique; its channels end in _<NAME> (upper case)
  std::optional<std::string> sensor_profile, can_interface, model, display_profile;
  /// sensor.id_offset: added to every CAN id of the sensor profile (two boards of one kind on
  /// one bus answer on ids apart by their board number)
  int can_id_offset = 0;

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("name", &name).Required());
    a->Section("sensor", [&](auto* s) {
      s->Visit(Field("profile", &sensor_profile));
      s->Visit(Field("interface", &can_interface));
      s->Visit(Field("id_offset", &can_id_offset).InRange(-0x1FFFFFFF, 0x1FFFFFFF));
    });
    a->Section("fe", [&](auto* f) { f->Visit(Field("model", &model)); });
    a->Section("display", [&](auto* d) { d->Visit(Field("profile", &display_profile)); });
  }
};

/// Every key is named in Serialize, with its range; the member initialisers are the
/// defaults. Channel names are checked after reading (lcm_io::CheckChannelNames).
struct BridgeConfig {
  std::string file;  ///< where it was read from ("" = defaults)

  // sensor:
  std::string sensor_profile = "uskin_4x4";  ///< shipped name or YAML path
  std::string can_interface = "can0";        ///< live mode (sedbridge run)
  int tare_scans = 0;                        ///< automatic tare over N quiet scans (0 = profile offsets)
  int can_id_offset = 0;                     ///< a finger's sensor.id_offset (FingerConfig; 0 = the profile's ids)

  // fe:
  std::string model = "B";      ///< model name or path (model::LoadFingertipModel)
  std::string preset = "fast";  ///< fast | balanced | accurate
  FeStepKind fe_step = FeStepKind::kScene;  ///< fe.step: scene | reduced | contact
  std::string compliance_cache_dir = "out/cache";  ///< fe.compliance_cache: precompute cache of fe.step contact
  bool face_contact = true;  ///< fe.face_contact: the leader press of fe.step contact touches skin faces too
  bool two_contacts = true;  ///< fe.two_contacts: fe.step contact may read a scan as two spheres at once
  bool finite_rods = true;   ///< fe.finite_rods: fe.step contact may read a rod that ends on the pad (an edge)
  RadiusTracking radius_tracking = RadiusTracking::kPosterior;  ///< fe.radius_tracking: posterior | steady
  /// fe.contact_tolerance: fe.step contact's leader press solves the penalty law to this
  /// fraction of its largest contact force (scene::PressToForceOptions::contact_relative_tolerance)
  double contact_tolerance = 1e-5;
  MerkelRegion merkel_region = MerkelRegion::kLayer;  ///< fe.merkel_region: layer | display
  FallbackAnswer fallback = FallbackAnswer::kPressureMap;  ///< fe.fallback
  sensors::SurfacePressureOptions surface_pressure;        ///< fe.surface_pressure: cell_mm, ridge, max_iterations

  // registration:
  PadRegistrationParams registration;

  // traction:
  TractionFieldOptions traction;
  ScanConditioningOptions conditioning;

  // display:
  std::string display_profile = "suction_4x4";  ///< shipped name (config/displays/NAME.yaml) or path
  /// display.rendering: inverse | curve; absent: inverse where the display can be rendered
  /// so (a device model of a kind with a mechanical load on the leader), else the curve.
  std::optional<RenderingMethod> display_rendering;
  /// display.render_iterations: inverse rendering's Levenberg-Marquardt iterations a scan at
  /// most (warm-started: what a scan leaves, the next goes on from). 3: the example's bridge
  /// latency p99 under 1 ms on the 2-core VM with the display fidelity at the peak unchanged
  /// (config/bridge/README.md).
  int display_render_iterations = 3;
  /// display.render_evaluations: inverse rendering's SED evaluations a scan at most,
  /// rejected trials included (render::InverseRendererOptions::max_evaluations; 0: bounded
  /// by the iterations alone). Bounds the worst scan's render, not only the typical one's.
  int display_render_evaluations = 0;
  /// display.fit_reduction: the inverse renderer's fit on the influence reduced per Merkel
  /// vertex, leaving out at most this share of the commands' strain energy at any vertex
  /// (render::DisplayRenderingOptions::fit_reduction: pins; 0: element by element).
  double display_fit_reduction = 1e-2;

  // rates:
  double status_Hz = 10;  ///< BRIDGE_STATUS rate (pipeline clock)
  double tick_Hz = 200;   ///< live mode: display Tick rate while no scan arrives

  // outputs:
  bool publish_sed = true;    ///< FINGERTIP_SED every step
  bool publish_scans = true;  ///< TACTILE_SCAN every scan
  /// DISPLAY_RENDERING (inverse rendering only) at most this often on the pipeline clock; 0:
  /// never. A viewer's message: after the command, so outside the scan-to-command latency.
  double rendering_Hz = 30;

  // lcm:
  lcm_io::LcmSettings lcm;

  // fingers: empty = one finger, the keys above (bridge/fingers.h: FingersOf).
  std::vector<FingerConfig> fingers;

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Section("sensor", [&](auto* s) {
      s->Visit(Field("profile", &sensor_profile));
      s->Visit(Field("interface", &can_interface));
      s->Visit(Field("tare_scans", &tare_scans).NonNegative());
    });
    a->Section("fe", [&](auto* f) {
      f->Visit(Field("model", &model));
      f->Visit(Field("preset", &preset).OneOf(scene::PresetNames()));
      f->Visit(Field("step", &fe_step));
      f->Visit(Field("compliance_cache", &compliance_cache_dir));
      f->Visit(Field("face_contact", &face_contact));
      f->Visit(Field("two_contacts", &two_contacts));
      f->Visit(Field("finite_rods", &finite_rods));
      f->Visit(Field("radius_tracking", &radius_tracking));
      f->Visit(Field("contact_tolerance", &contact_tolerance).InRange(1e-12, 0.1));
      f->Visit(Field("merkel_region", &merkel_region));
      f->Visit(Field("fallback", &fallback));
      f->Section("surface_pressure", [&](auto* p) {
        p->Visit(Field("cell_mm", &surface_pressure.cell_mm).InRange(0.1, 5.0));
        p->Visit(Field("ridge", &surface_pressure.ridge).Positive());
        p->Visit(Field("max_iterations", &surface_pressure.max_iterations).InRange(1, 1000));
      });
    });
    a->Section("registration", [&](auto* g) {
      g->Visit(Field("offset_mm", &registration.offset_mm));
      g->Visit(Field("rotation_deg", &registration.rotation_deg));
      g->Visit(Field("scale", &registration.scale).Positive());
    });
    a->Section("traction", [&](auto* t) {
      t->Visit(Field("kernel_sigma_mm", &traction.kernel_sigma_mm).NonNegative());
      t->Visit(Field("min_facing", &traction.min_facing).InRange(-1, 1));
      t->Visit(Field("max_depth_mm", &traction.max_depth_mm).Positive());
      t->Visit(Field("nodal_load", &traction.nodal_load));
      t->Visit(Field("invalid_taxels", &conditioning.invalid));
      t->Visit(Field("max_invalid_fraction", &conditioning.max_invalid_fraction).InRange(0, 1));
      t->Visit(Field("noise_floor_Pa", &conditioning.noise_floor_Pa).NonNegative());
    });
    a->Section("display", [&](auto* d) {
      d->Visit(Field("profile", &display_profile).Required());
      d->Visit(Field("rendering", &display_rendering));
      d->Visit(Field("render_iterations", &display_render_iterations).InRange(1, 200));
      d->Visit(Field("render_evaluations", &display_render_evaluations).InRange(0, 1000));
      d->Visit(Field("fit_reduction", &display_fit_reduction).InRange(0, 0.5));
    });
    a->Section("rates", [&](auto* q) {
      q->Visit(Field("status_Hz", &status_Hz).Unit("Hz").InRange(kMinStatus_Hz, kMaxStatus_Hz));
      q->Visit(Field("tick_Hz", &tick_Hz).Unit("Hz").InRange(kMinTick_Hz, kMaxTick_Hz));
    });
    a->Section("outputs", [&](auto* o) {
      o->Visit(Field("publish_sed", &publish_sed));
      o->Visit(Field("publish_scans", &publish_scans));
      o->Visit(Field("rendering_Hz", &rendering_Hz).Unit("Hz").InRange(0, 1000));
    });
    a->Visit(Field("lcm", &lcm));
    a->Visit(Field("fingers", &fingers));
  }
};

/// Reads a bridge YAML. Throws config::ConfigError.
BridgeConfig LoadBridgeConfig(const std::string& path);
/// Same from text (`file` is used in messages).
BridgeConfig ParseBridgeConfig(const std::string& yaml_text, const std::string& file);

/// The shipped default config (config/bridge/default.yaml, resolved from any directory).
std::string DefaultBridgeConfigPath();

}  // namespace sedbridge::bridge
