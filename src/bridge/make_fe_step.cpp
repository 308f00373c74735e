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

std::unique_ptr<FeStep> MakeFeStep(const BridgeConfig& config, const sensors::SensorProfile& profile,
                                   bool full_field, const display::DisplayProfile* display) {
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
    return MakeFeStep(map, profile, false, display);
  }
  if (config.fe_step == FeStepKind::kContact) {
    // The pressure map stays as the fallback for scans the reconstruction cannot explain.
    BridgeConfig map = config;
    map.fe_step = FeStepKind::kReduced;
    scene::FingertipComplianceOptions leader = contact::LeaderComplianceOptions(config.compliance_cache_dir, config.face_contact);
    leader.contact.full_field = full_field;
    return std::make_unique<ContactFeStep>(config.model, profile, PadRegistration(profile.taxels, config.registration),
                                           MakeFeStep(map, profile, false, display), std::move(leader),
                                           ReconstructionOptionsOf(config), ReconstructedPressOptions(config), region);
  }
  if (config.fe_step == FeStepKind::kReduced)
    return std::make_unique<ReducedLinearFeStep>(BridgeSceneDescription(config.model, config.preset), profile,
                                                 PadRegistration(profile.taxels, config.registration), config.traction,
                                                 region);
  return std::make_unique<SceneFeStep>(BridgeSceneDescription(config.model, config.preset), profile,
                                       PadRegistration(profile.taxels, config.registration), config.traction, region);
}

}  // namespace sedbridge::bridge
