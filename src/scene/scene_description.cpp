#include "scene/scene_description.h"

#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>

#include "display/display_profile.h"

#include "common/yaml_read_archive.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::scene {
namespace {

using config::MapReader;

// `node[key]` of a mapping node, or the mapping itself when the key is absent (for errors).
YAML::Node At(const YAML::Node& map, const char* key) { return map[key] ? map[key] : map; }

// The fast preset's solver. Without contact the matrix is constant: factorized once, one
// back-substitution a step (CHOLMOD's is ~3x faster than the LDL^T's on B). A quasi-static
// contact press that the compliance method can answer gets it: the contact solved on the
// precomputed compliance of the pad, no FE solve a step (the paper's press 25x faster than
// the linear FE, same answer: docs/performance.md). Other contact scenes get the PCG
// preconditioned by the rest factor: contact changes the matrix every step, and
// refactorizing (~11 ms on model B) costs more than the PCG.
SolverKind FastPresetSolver(const SceneDescription& s) {
  if (!s.contact) return SolverKind::kCholmod;
  if (s.integrator.kind == fem::IntegratorKind::kQuasiStatic) {
    SceneDescription trial = s;
    trial.solver = SolverKind::kCompliance;
    try {
      ComplianceOptionsFromScene(trial);
      return SolverKind::kCompliance;
    } catch (const std::invalid_argument&) {
      // something the method cannot do (full_sed, a tracked bone, ...): the FE step
    }
  }
  return SolverKind::kPcgWarp;
}

// "0.5" for messages (std::to_string prints 0.500000).
std::string Number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// Key `display`: the profile loaded, one command per actuator, each within [0, the
// actuator's safety maximum] (what the limiter would let reach the finger).
DisplayLoadSection ReadDisplayLoad(MapReader& scene) {
  MapReader d = scene.Child("display");
  DisplayLoadSection load;
  const YAML::Node profile_node = d.Node("profile");
  const std::string name = config::As<std::string>(profile_node, d.file(), "profile");
  const std::string path = display::ResolveDisplayProfilePath(name);
  if (!std::filesystem::exists(path))
    d.Fail(profile_node, "display profile '" + name + "': no such file (" + path +
                             "; a shipped name is a file of config/displays/)");
  load.profile = display::LoadDisplayProfile(path);  // its own errors name its file:line:column
  if (!load.profile.has_device_model())
    d.Fail(profile_node, "display profile '" + name + "' (" + display::ToString(load.profile.kind) +
                             ") has no device model (key `device`): no mechanical load on the finger to press" +
                             (load.profile.kind == display::DisplayKind::kElectrotactile
                                  ? " (electrotactile: its rendering is against the SA1 rate estimate)"
                                  : ""));
  const YAML::Node commands_node = d.Node("commands");
  load.commands = config::As<std::vector<double>>(commands_node, d.file(), "commands");
  const display::DisplayProfile& p = load.profile;
  if (load.commands.size() != p.size())
    d.Fail(commands_node, "'commands' has " + std::to_string(load.commands.size()) + " entries; " + p.name + " has " +
                              std::to_string(p.size()) + " actuators (one command each, in its order)");
  for (std::size_t i = 0; i < load.commands.size(); ++i) {
    const double max = p.safety.max_per_actuator.empty() ? p.safety.max : p.safety.max_per_actuator[i];
    if (load.commands[i] < 0 || load.commands[i] > max)
      d.Fail(commands_node[i], "command " + std::to_string(i) + " (" + Number(load.commands[i]) + " " + p.unit +
                                   ") is outside [0, " + Number(max) + "] " + p.unit + ", actuator " +
                                   std::to_string(i) + "'s safety maximum in " + p.file +
                                   " (the limiter lets no more reach the finger)");
  }
  d.Finish();
  return load;
}

SceneDescription Parse(const config::YamlDocument& doc) {
  MapReader r(doc.root, doc.file);
  // The preset gives defaults and every key given overrides them: read the preset name,
  // apply it, then read every key over it.
  SceneDescription s;
  {
    SceneDescription probe;
    config::YamlReadArchive probe_archive(&r);
    probe.Serialize(&probe_archive);
    if (!probe.preset.empty()) {
      try {
        ApplyPreset(probe.preset, s);
      } catch (const std::invalid_argument& e) {
        r.Fail(r.Node("preset"), e.what());
      }
    }
  }
  config::YamlReadArchive archive(&r);
  s.Serialize(&archive);
  s.file = doc.file;
  if (s.integrator.kind == fem::IntegratorKind::kQuasiStatic) s.dt_s = 1.0 / s.steps;
  const YAML::Node solver_node = doc.root["solver"];
  const bool solver_type_given = solver_node && solver_node["type"];
  if (!s.solver_cache_dir.empty() && s.solver != SolverKind::kCompliance)
    r.Fail(At(solver_node, "cache_dir"), "'cache_dir' is for solver type 'compliance'");

  if (s.bone) {
    MapReader b(doc.root["bone"], doc.file);  // keys checked by the archive
    if (b.OptionalChoice("mode", {"fixed", "tracked"}, "fixed") == "tracked") {
      MapReader m = b.Child("motion");
      s.bone->motion = std::make_shared<geometry::Trajectory>(geometry::ParseMotion(m, Eigen::Isometry3d::Identity()));
      m.Finish();
    } else if (b.Has("motion")) {
      b.Fail(b.Node("motion"), "'motion' needs mode: tracked");
    }
  }
  if (s.contact) {
    MapReader c(doc.root["contact"], doc.file);
    s.contact->objects_pad_frame = geometry::ParseRigidObjects(c, "objects");
    if (s.contact->objects_pad_frame.empty()) c.Fail(c.Node("objects"), "'objects' is empty");
  }
  if (doc.root["display"]) {
    s.display = ReadDisplayLoad(r);
    // One load at a time, solved as the display rendering solves it (render/display_press.h).
    if (s.contact) r.Fail(r.Node("display"), "'display' and 'contact' are two loads; a display press has no contact object");
    if (s.solver != SolverKind::kCompliance)
      r.Fail(r.Node("display"), "a display press is solved by the compliance method, as the display rendering is: "
                                "the scene needs solver.type: compliance (a linear, quasi-static scene with the bone fixed)");
  }
  // The preset was applied before `contact` was read; its solver choice depends on it.
  if (s.preset == "fast" && s.contact && !solver_type_given) s.solver = FastPresetSolver(s);

  if (s.friction) {
    if (!s.contact) r.Fail(r.Node("friction"), "'friction' needs a 'contact' section");
    if (!(s.friction->anisotropy > 0)) s.friction.reset();  // a = 0 is frictionless: nothing to build
  }
  // The compliance solver exists only for linear quasi-static scenes: say so at the key.
  if (s.solver == SolverKind::kCompliance) {
    try {
      ComplianceOptionsFromScene(s);
    } catch (const std::invalid_argument& e) {
      r.Fail(r.Node("solver"), e.what());
    }
  }
  r.Finish();
  return s;
}

}  // namespace

const config::EnumNames<SolverKind>& NamesOf(SolverKind) {
  static const config::EnumNames<SolverKind> names{
      {SolverKind::kLdlt, "ldlt"},           {SolverKind::kCholmod, "cholmod"},
      {SolverKind::kPcgJacobi, "pcg_jacobi"}, {SolverKind::kPcgWarp, "pcg_warp"},
      {SolverKind::kPcgWarpLdlt, "pcg_warp_ldlt"}, {SolverKind::kPcgWarpIchol, "pcg_warp_ichol"},
      {SolverKind::kCompliance, "compliance"}};
  return names;
}

const char* ToString(SolverKind kind) { return config::NameCStrOf(kind); }

SolverKind SolverKindFromString(const std::string& name) { return config::ParseEnum<SolverKind>(name, "solver type"); }

SceneDescription ReadSceneDescription(const std::string& path) { return Parse(config::LoadYamlFile(path)); }

SceneDescription ParseSceneDescription(const std::string& text, const std::string& file) {
  return Parse(config::LoadYamlString(text, file));
}

const config::EnumNames<SceneElasticity>& NamesOf(SceneElasticity) {
  static const config::EnumNames<SceneElasticity> names{{SceneElasticity::kCorotational, "corotational"},
                                                        {SceneElasticity::kLinear, "linear"},
                                                        {SceneElasticity::kNodalPressure, "nodal_pressure"}};
  return names;
}

SceneElasticity SceneDescription::elasticity_name() const {
  if (nodal_pressure) return SceneElasticity::kNodalPressure;
  return elasticity == fem::ElasticFormulation::kLinear ? SceneElasticity::kLinear : SceneElasticity::kCorotational;
}

void SceneDescription::set_elasticity(SceneElasticity e) {
  elasticity = e == SceneElasticity::kLinear ? fem::ElasticFormulation::kLinear : fem::ElasticFormulation::kCorotational;
  nodal_pressure = e == SceneElasticity::kNodalPressure;
}

void ApplyPreset(const std::string& name, SceneDescription& s) {
  // Chosen from the measured accuracy-cost study (docs/accuracy-cost.md).
  // Each preset picks its element: the nodal pressure tet is only ever asked for by name.
  switch (config::ParseEnum<Preset>(name, "preset")) {
  case Preset::kFast:
    s.nodal_pressure = false;
    s.elasticity = fem::ElasticFormulation::kLinear;
    s.solver = FastPresetSolver(s);
    s.integrator.newton_iterations = 1;
    break;
  case Preset::kBalanced:
    s.nodal_pressure = false;
    s.elasticity = fem::ElasticFormulation::kCorotational;
    s.solver = SolverKind::kPcgWarp;
    s.pcg.relative_tolerance = 1e-4;
    s.pcg.max_iterations = 50;
    s.integrator.newton_iterations = 1;
    break;
  case Preset::kAccurate:
    s.nodal_pressure = false;
    s.elasticity = fem::ElasticFormulation::kCorotational;
    // Newton's systems by PCG with the warped rest factor, to 1e-6: the quasi-static press's
    // outputs are byte-identical to refactorizing CHOLMOD every iteration, a backward Euler
    // step's within 1e-8, in a third to a half of the time (docs/performance.md).
    s.solver = SolverKind::kPcgWarp;
    s.pcg.relative_tolerance = 1e-6;
    s.integrator.newton_iterations = 3;
    break;
  }
}

}  // namespace sedbridge::scene
