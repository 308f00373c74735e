#include "bridge/bridge_config.h"

#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "common/resource_path.h"
#include "common/yaml_reader.h"

namespace sedbridge::bridge {
namespace {

using config::MapReader;

double Positive(MapReader& r, const std::string& key, double fallback) {
  if (!r.Has(key)) return fallback;
  const double v = r.Required<double>(key);
  if (!(std::isfinite(v) && v > 0)) r.Fail(r.Node(key), "'" + key + "' must be a finite number > 0");
  return v;
}

double NonNegative(MapReader& r, const std::string& key, double fallback) {
  if (!r.Has(key)) return fallback;
  const double v = r.Required<double>(key);
  if (!(std::isfinite(v) && v >= 0)) r.Fail(r.Node(key), "'" + key + "' must be a finite number >= 0");
  return v;
}

// A finite value in [lo, hi]; the bounds are named in the message.
double InRange(MapReader& r, const std::string& key, double fallback, double lo, double hi, const char* unit) {
  if (!r.Has(key)) return fallback;
  const double v = r.Required<double>(key);
  if (!(v >= lo && v <= hi)) {
    std::ostringstream m;
    m << "'" << key << "' must be in [" << lo << ", " << hi << "] " << unit << " (got " << v << ")";
    r.Fail(r.Node(key), m.str());
  }
  return v;
}

BridgeConfig Parse(const config::YamlDocument& doc) {
  BridgeConfig c;
  c.file = doc.file;
  if (!doc.root || doc.root.IsNull()) return c;
  MapReader r(doc.root, doc.file);
  if (r.Has("sensor")) {
    MapReader s = r.Child("sensor");
    c.sensor_profile = s.Optional<std::string>("profile", c.sensor_profile);
    c.can_interface = s.Optional<std::string>("interface", c.can_interface);
    c.tare_scans = s.Optional<int>("tare_scans", c.tare_scans);
    if (c.tare_scans < 0) s.Fail(s.Node("tare_scans"), "'tare_scans' must be >= 0");
    s.Finish();
  }
  if (r.Has("fe")) {
    MapReader f = r.Child("fe");
    c.model = f.Optional<std::string>("model", c.model);
    c.preset = f.OptionalChoice("preset", {"fast", "balanced", "accurate"}, c.preset);
    c.fe_step = FeStepKindFromString(f.OptionalChoice("step", {"scene", "reduced", "contact"}, ToString(c.fe_step)));
    c.compliance_cache_dir = f.Optional<std::string>("compliance_cache", c.compliance_cache_dir);
    if (c.fe_step != FeStepKind::kScene && c.preset != "fast")
      f.Fail(f.Node("step"), "'step: reduced' and 'step: contact' need 'preset: fast' (a linear model)");
    f.Finish();
  }
  if (r.Has("registration")) {
    MapReader g = r.Child("registration");
    if (g.Has("offset_mm")) {
      const auto v = g.Required<std::vector<double>>("offset_mm");
      if (v.size() != 2 || !std::isfinite(v[0]) || !std::isfinite(v[1]))
        g.Fail(g.Node("offset_mm"), "'offset_mm' must be [x, y] (finite)");
      c.registration.offset_mm = Eigen::Vector2d(v[0], v[1]);
    }
    c.registration.rotation_deg = g.Optional<double>("rotation_deg", 0.0);
    if (!std::isfinite(c.registration.rotation_deg)) g.Fail(g.Node("rotation_deg"), "'rotation_deg' must be finite");
    c.registration.scale = Positive(g, "scale", 1.0);
    g.Finish();
  }
  if (r.Has("traction")) {
    MapReader t = r.Child("traction");
    c.traction.kernel_sigma_mm = NonNegative(t, "kernel_sigma_mm", c.traction.kernel_sigma_mm);
    c.conditioning.fill_sigma_mm = c.traction.kernel_sigma_mm;
    c.traction.min_facing = t.Optional<double>("min_facing", c.traction.min_facing);
    if (!(c.traction.min_facing >= -1 && c.traction.min_facing <= 1))
      t.Fail(t.Node("min_facing"), "'min_facing' must be in [-1, 1]");
    c.traction.max_depth_mm = Positive(t, "max_depth_mm", c.traction.max_depth_mm);
    c.traction.nodal_load = t.OptionalChoice("nodal_load", {"lumped", "consistent"}, "lumped") == "consistent"
                                ? NodalLoad::kConsistent
                                : NodalLoad::kLumped;
    c.conditioning.invalid = t.OptionalChoice("invalid_taxels", {"fill", "zero"}, "fill") == "zero"
                                 ? InvalidTaxelPolicy::kZero
                                 : InvalidTaxelPolicy::kFill;
    c.conditioning.max_invalid_fraction = t.Optional<double>("max_invalid_fraction", c.conditioning.max_invalid_fraction);
    if (!(c.conditioning.max_invalid_fraction >= 0 && c.conditioning.max_invalid_fraction <= 1))
      t.Fail(t.Node("max_invalid_fraction"), "'max_invalid_fraction' must be in [0, 1]");
    c.conditioning.noise_floor_Pa = NonNegative(t, "noise_floor_Pa", c.conditioning.noise_floor_Pa);
    t.Finish();
  }
  if (r.Has("display")) {
    MapReader d = r.Child("display");
    c.display_profile = d.Required<std::string>("profile");
    d.Finish();
  }
  if (r.Has("rates")) {
    MapReader q = r.Child("rates");
    c.status_Hz = InRange(q, "status_Hz", c.status_Hz, kMinStatus_Hz, kMaxStatus_Hz, "Hz");
    c.tick_Hz = InRange(q, "tick_Hz", c.tick_Hz, kMinTick_Hz, kMaxTick_Hz, "Hz");
    q.Finish();
  }
  if (r.Has("outputs")) {
    MapReader o = r.Child("outputs");
    c.publish_sed = o.Optional<bool>("publish_sed", c.publish_sed);
    c.publish_scans = o.Optional<bool>("publish_scans", c.publish_scans);
    o.Finish();
  }
  if (r.Has("lcm")) {
    MapReader l = r.Child("lcm");
    c.lcm = lcm_io::ParseLcmSettings(l);
  }
  r.Finish();
  return c;
}

}  // namespace

const char* ToString(FeStepKind kind) {
  switch (kind) {
    case FeStepKind::kScene: return "scene";
    case FeStepKind::kReduced: return "reduced";
    case FeStepKind::kContact: return "contact";
  }
  return "?";
}

FeStepKind FeStepKindFromString(const std::string& name) {
  for (FeStepKind k : {FeStepKind::kScene, FeStepKind::kReduced, FeStepKind::kContact})
    if (name == ToString(k)) return k;
  throw std::invalid_argument("unknown fe.step '" + name + "' (scene, reduced, contact)");
}

BridgeConfig LoadBridgeConfig(const std::string& path) { return Parse(config::LoadYamlFile(path)); }

BridgeConfig ParseBridgeConfig(const std::string& yaml_text, const std::string& file) {
  return Parse(config::LoadYamlString(yaml_text, file));
}

std::string DefaultBridgeConfigPath() { return config::ResolveResource("config/bridge/default.yaml"); }

}  // namespace sedbridge::bridge
