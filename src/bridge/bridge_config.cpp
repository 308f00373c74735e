#include "bridge/bridge_config.h"

#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "bridge/fingers.h"
#include "common/resource_path.h"
#include "common/yaml_read_archive.h"

namespace sedbridge::bridge {
namespace {

using config::MapReader;

BridgeConfig Parse(const config::YamlDocument& doc) {
  BridgeConfig c;
  c.file = doc.file;
  if (!doc.root || doc.root.IsNull()) return c;
  MapReader r(doc.root, doc.file);
  config::YamlReadArchive archive(&r);
  c.Serialize(&archive);
  // One kernel width for the traction and the fill of invalid taxels.
  c.conditioning.fill_sigma_mm = c.traction.kernel_sigma_mm;
  if (c.fe_step != FeStepKind::kScene && c.preset != "fast")
    r.Fail(doc.root["fe"]["step"], "'step: reduced' and 'step: contact' need 'preset: fast' (a linear model)");
  // The inverse renderer fits the layer under the display; fe.merkel_region: display computes
  // only the vertices the curve samples, too few to fit (their neighbours would be free).
  if (c.display_rendering == RenderingMethod::kInverse && c.merkel_region == MerkelRegion::kDisplay)
    r.Fail(doc.root["display"]["rendering"],
           "'rendering: inverse' needs 'fe.merkel_region: layer' (the inverse renderer fits the SED of the layer under "
           "the display; 'merkel_region: display' computes only the vertices the curve samples)");
  if (r.Has("lcm")) lcm_io::CheckChannelNames(MapReader(doc.root["lcm"], doc.file));
  CheckFingers(c, r);
  r.Finish();
  return c;
}

}  // namespace

const config::EnumNames<FeStepKind>& NamesOf(FeStepKind) {
  static const config::EnumNames<FeStepKind> names{
      {FeStepKind::kScene, "scene"}, {FeStepKind::kReduced, "reduced"}, {FeStepKind::kContact, "contact"}};
  return names;
}

const char* ToString(FeStepKind kind) { return config::NameCStrOf(kind); }

const config::EnumNames<MerkelRegion>& NamesOf(MerkelRegion) {
  static const config::EnumNames<MerkelRegion> names{{MerkelRegion::kLayer, "layer"},
                                                     {MerkelRegion::kDisplay, "display"}};
  return names;
}

const char* ToString(MerkelRegion region) { return config::NameCStrOf(region); }

const config::EnumNames<RadiusTracking>& NamesOf(RadiusTracking) {
  static const config::EnumNames<RadiusTracking> names{{RadiusTracking::kSteady, "steady"},
                                                       {RadiusTracking::kPosterior, "posterior"}};
  return names;
}

const char* ToString(RadiusTracking tracking) { return config::NameCStrOf(tracking); }

const config::EnumNames<RenderingMethod>& NamesOf(RenderingMethod) {
  static const config::EnumNames<RenderingMethod> names{{RenderingMethod::kInverse, "inverse"},
                                                        {RenderingMethod::kCurve, "curve"}};
  return names;
}

const char* ToString(RenderingMethod method) { return config::NameCStrOf(method); }

FeStepKind FeStepKindFromString(const std::string& name) { return config::ParseEnum<FeStepKind>(name, "fe.step"); }

BridgeConfig LoadBridgeConfig(const std::string& path) { return Parse(config::LoadYamlFile(path)); }

BridgeConfig ParseBridgeConfig(const std::string& yaml_text, const std::string& file) {
  return Parse(config::LoadYamlString(yaml_text, file));
}

std::string DefaultBridgeConfigPath() { return config::ResolveResource("config/bridge/default.yaml"); }

}  // namespace sedbridge::bridge
