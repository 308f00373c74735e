#include "bridge/make_fe_step.h"

#include <cstdio>
#include <optional>

#include "bridge/contact_fe_step.h"
#include "contact/contact_object.h"
#include "bridge/reduced_linear_fe_step.h"
#include "bridge/scene_fe_step.h"
#include "display/sed_to_command_mapping.h"

namespace sedbridge::bridge {

model::MerkelVertexFilter DisplayFootprint(const display::DisplayProfile& display) {
  auto mapping = std::make_shared<const display::SedToCommandMapping>(display);
  char what[256];
  std::snprintf(what, sizeof what,
                "fe.merkel_region: display, the %zu sites of display '%s' within %g mm in x-y and z in [%g, %g] mm: "
                "do they lie on the leader's pad?",
                mapping->size(), display.name.c_str(), mapping->params().radius_mm, mapping->params().z_min_mm,
                mapping->params().z_max_mm);
  return {[mapping](const Eigen::Vector3d& p_mm) { return mapping->Reads(p_mm.x(), p_mm.y(), p_mm.z()); }, what};
}

namespace {

// fe.step contact's leader: from `leaders` when another finger built the same (model, Merkel
// region, contact options), else built here and left in `leaders` for the next.
std::unique_ptr<FeStep> MakeContactStep(const BridgeConfig& config, const sensors::SensorProfile& profile,
                                        std::unique_ptr<FeStep> fallback, scene::FingertipComplianceOptions leader,
                                        const model::MerkelVertexFilter& region, LeaderModelCache* leaders) {
  const PadRegistration registration(profile.taxels, config.registration);
  auto surface = [&](std::unique_ptr<ContactFeStep> step) -> std::unique_ptr<FeStep> {
    if (config.fallback != FallbackAnswer::kPressureMap)
      step->UseSurfacePressure(profile, registration, config.surface_pressure,
                               config.fallback == FallbackAnswer::kSurfacePressureAndFlagged);
    return step;
  };
  if (!leaders)
    return surface(std::make_unique<ContactFeStep>(config.model, profile, registration, std::move(fallback),
                                                   std::move(leader), ReconstructionOptionsOf(config),
                                                   ReconstructedPressOptions(config), region));
  const std::string model_key = config.model + "|" + (region ? region.what : std::string("layer"));
  const std::string op_key = model_key + "|" + config.compliance_cache_dir + "|" + (config.face_contact ? "faces" : "nodes") +
                             "|" + (leader.contact.full_field ? "full" : "contact");
  auto model = leaders->Model(model_key, [&] { return LoadBridgeModel(config.model, region); });
  leader.contact.shared_operator = leaders->Operator(op_key);
  const bool first = !leader.contact.shared_operator;
  auto step = std::make_unique<ContactFeStep>(config.model, profile, registration, std::move(fallback),
                                              std::move(leader), ReconstructionOptionsOf(config),
                                              ReconstructedPressOptions(config), region, std::move(model));
  if (first) leaders->Remember(op_key, step->leader_operator());
  return surface(std::move(step));
}

}  // namespace

std::unique_ptr<FeStep> MakeFeStep(const BridgeConfig& config, const sensors::SensorProfile& profile,
                                   bool full_field, const display::DisplayProfile* display, LeaderModelCache* leaders) {
  model::MerkelVertexFilter region;
  std::optional<display::DisplayProfile> loaded;  // the config's display, read once for the nested steps
  if (config.merkel_region == MerkelRegion::kDisplay) {
    if (!display) display = &loaded.emplace(display::LoadNamedDisplayProfile(config.display_profile));
    region = DisplayFootprint(*display);
  }
  if (config.fe_step == FeStepKind::kContact && (!profile.has_forward_model || profile.axes != 3)) {
    std::fprintf(stderr,
                 "note: fe.step contact needs a three-axis sensor profile with a calibrated forward_model ('%s' has "
                 "none); using the pressure map (fe.step reduced)\n",
                 profile.name.c_str());
    BridgeConfig map = config;
    map.fe_step = FeStepKind::kReduced;
    return MakeFeStep(map, profile, false, display, leaders);
  }
  if (config.fe_step == FeStepKind::kContact) {
    // The pressure map stays as the fallback for scans the reconstruction cannot explain.
    BridgeConfig map = config;
    map.fe_step = FeStepKind::kReduced;
    scene::FingertipComplianceOptions leader = contact::LeaderComplianceOptions(config.compliance_cache_dir, config.face_contact);
    leader.contact.full_field = full_field;
    return MakeContactStep(config, profile, MakeFeStep(map, profile, false, display, leaders), std::move(leader),
                           region, leaders);
  }
  if (config.fe_step == FeStepKind::kReduced) {
    // A hand's fingers share the bridge's registration and traction keys: the model, preset,
    // sensor profile and Merkel region tell their precomputes apart.
    std::string key = config.model + "|" + config.preset + "|" + profile.name + "|" + std::to_string(profile.axes) +
                      "|" + (region ? region.what : std::string("layer"));
    char at[64];
    for (const sensors::TaxelPosition& t : profile.taxels) {  // two profiles of one name, other pads
      std::snprintf(at, sizeof at, "|%.17g,%.17g", t.x_mm, t.y_mm);
      key += at;
    }
    if (leaders)
      if (auto shared = leaders->Fallback(key)) return std::make_unique<ReducedLinearFeStep>(std::move(shared));
    auto step = std::make_unique<ReducedLinearFeStep>(BridgeSceneDescription(config.model, config.preset), profile,
                                                      PadRegistration(profile.taxels, config.registration),
                                                      config.traction, region);
    if (leaders) leaders->RememberFallback(key, step->precompute());
    return step;
  }
  return std::make_unique<SceneFeStep>(BridgeSceneDescription(config.model, config.preset), profile,
                                       PadRegistration(profile.taxels, config.registration), config.traction, region);
}

}  // namespace sedbridge::bridge
