#include "scene/scene_description.h"

#include <stdexcept>

#include "common/yaml_reader.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::scene {
namespace {

using config::MapReader;

double NonNegative(MapReader& r, const std::string& key, double fallback) {
  const double v = r.Optional<double>(key, fallback);
  if (!(v >= 0) || !std::isfinite(v)) r.Fail(r.Has(key) ? r.Node(key) : r.node(), "'" + key + "' must be a finite number >= 0");
  return v;
}

double Positive(MapReader& r, const std::string& key, double fallback) {
  const double v = r.Optional<double>(key, fallback);
  if (!(v > 0) || !std::isfinite(v)) r.Fail(r.Has(key) ? r.Node(key) : r.node(), "'" + key + "' must be a finite number > 0");
  return v;
}

SceneDescription Parse(const config::YamlDocument& doc) {
  SceneDescription s;
  s.file = doc.file;
  MapReader r(doc.root, doc.file);
  s.model = r.Required<std::string>("model");
  if (r.Has("preset")) {
    const YAML::Node n = r.Node("preset");
    s.preset = config::As<std::string>(n, doc.file, "preset");
    try {
      ApplyPreset(s.preset, s);
    } catch (const std::invalid_argument& e) {
      r.Fail(n, e.what());
    }
  }
  if (r.Has("elasticity")) {
    const std::string e = r.RequiredChoice("elasticity", {"corotational", "linear", "nodal_pressure"});
    s.elasticity = e == "linear" ? fem::ElasticFormulation::kLinear : fem::ElasticFormulation::kCorotational;
    s.nodal_pressure = e == "nodal_pressure";
  }

  if (r.Has("dynamics")) {
    MapReader d = r.Child("dynamics");
    if (d.Has("integrator"))
      s.integrator.kind = d.RequiredChoice("integrator", {"backward_euler", "quasi_static"}) == "quasi_static"
                              ? fem::IntegratorKind::kQuasiStatic
                              : fem::IntegratorKind::kBackwardEuler;
    s.dt_s = Positive(d, "dt_s", s.dt_s);
    s.steps = d.Optional<int>("steps", s.steps);
    if (s.steps < 1 || s.steps > kMaxSceneSteps)
      d.Fail(d.Node("steps"), "'steps' must be in [1, " + std::to_string(kMaxSceneSteps) + "]");
    s.integrator.newton_iterations = d.Optional<int>("newton_iterations", s.integrator.newton_iterations);
    if (s.integrator.newton_iterations < 1) d.Fail(d.Node("newton_iterations"), "'newton_iterations' must be >= 1");
    s.integrator.newton_tolerance_m = Positive(d, "newton_tolerance_mm", s.integrator.newton_tolerance_m * 1e3) * 1e-3;
    s.integrator.rayleigh_alpha_1_s = NonNegative(d, "rayleigh_alpha_1_s", s.integrator.rayleigh_alpha_1_s);
    s.rayleigh_beta_s = NonNegative(d, "rayleigh_beta_s", s.rayleigh_beta_s);
    d.Finish();
  }
  if (s.integrator.kind == fem::IntegratorKind::kQuasiStatic) s.dt_s = 1.0 / s.steps;

  bool solver_type_given = false;
  if (r.Has("solver")) {
    MapReader so = r.Child("solver");
    solver_type_given = so.Has("type");
    if (so.Has("type"))
      s.solver = SolverKindFromString(so.RequiredChoice("type", {"ldlt", "cholmod", "pcg_jacobi", "pcg_warp", "pcg_warp_ldlt", "pcg_warp_ichol", "compliance"}));
    if (so.Has("cache_dir")) {
      if (s.solver != SolverKind::kCompliance) so.Fail(so.Node("cache_dir"), "'cache_dir' is for solver type 'compliance'");
      s.solver_cache_dir = so.Required<std::string>("cache_dir");
    }
    s.pcg.relative_tolerance = Positive(so, "tolerance", s.pcg.relative_tolerance);
    s.pcg.max_iterations = so.Optional<int>("max_iterations", s.pcg.max_iterations);
    if (s.pcg.max_iterations < 1) so.Fail(so.Node("max_iterations"), "'max_iterations' must be >= 1");
    s.pcg.fallback_to_direct = so.Optional<bool>("fallback_to_direct", s.pcg.fallback_to_direct);
    so.Finish();
  }

  if (r.Has("bone")) {
    MapReader b = r.Child("bone");
    BoneSection bone;
    const std::string mode = b.OptionalChoice("mode", {"fixed", "tracked"}, "fixed");
    bone.spring.stiffness_N_m = Positive(b, "stiffness_N_m", bone.spring.stiffness_N_m);
    bone.spring.damping_N_s_m = NonNegative(b, "damping_N_s_m", bone.spring.damping_N_s_m);
    bone.spring.anisotropy = NonNegative(b, "anisotropy", bone.spring.anisotropy);
    if (mode == "tracked") {
      MapReader m = b.Child("motion");
      bone.motion = std::make_shared<geometry::Trajectory>(geometry::ParseMotion(m, Eigen::Isometry3d::Identity()));
      m.Finish();
    } else if (b.Has("motion")) {
      b.Fail(b.Node("motion"), "'motion' needs mode: tracked");
    }
    b.Finish();
    s.bone = bone;
  }

  if (r.Has("contact")) {
    MapReader c = r.Child("contact");
    ContactSection contact;
    contact.params.stiffness_N_m = Positive(c, "stiffness_N_m", contact.params.stiffness_N_m);
    contact.params.damping_N_s_m = NonNegative(c, "damping_N_s_m", contact.params.damping_N_s_m);
    contact.objects_pad_frame = geometry::ParseRigidObjects(c.Node("objects"), doc.file);
    if (contact.objects_pad_frame.empty()) c.Fail(c.Node("objects"), "'objects' is empty");
    c.Finish();
    s.contact = std::move(contact);
  }
  // The preset was applied before `contact` was read; its solver choice depends on it.
  if (s.preset == "fast" && s.contact && !solver_type_given) s.solver = SolverKind::kPcgWarp;

  if (r.Has("friction")) {
    MapReader f = r.Child("friction");
    if (!s.contact) f.Fail("'friction' needs a 'contact' section");
    FrictionSection fr;
    fr.anisotropy = NonNegative(f, "anisotropy", 0.0);
    fr.coulomb_mu = NonNegative(f, "coulomb_mu", 0.0);
    f.Finish();
    if (fr.anisotropy > 0) s.friction = fr;  // a = 0 is frictionless: nothing to build
  }

  s.surface_traction = r.Optional<bool>("surface_traction", false);

  if (r.Has("outputs")) {
    MapReader o = r.Child("outputs");
    s.outputs.merkel_sed = o.Optional<bool>("merkel_sed", s.outputs.merkel_sed);
    s.outputs.full_sed = o.Optional<bool>("full_sed", s.outputs.full_sed);
    s.outputs.vtu_every = o.Optional<int>("vtu_every", s.outputs.vtu_every);
    if (s.outputs.vtu_every < 0) o.Fail(o.Node("vtu_every"), "'vtu_every' must be >= 0");
    o.Finish();
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

const char* ToString(SolverKind kind) {
  switch (kind) {
    case SolverKind::kCholmod: return "cholmod";
    case SolverKind::kLdlt: return "ldlt";
    case SolverKind::kPcgJacobi: return "pcg_jacobi";
    case SolverKind::kPcgWarp: return "pcg_warp";
    case SolverKind::kPcgWarpLdlt: return "pcg_warp_ldlt";
    case SolverKind::kPcgWarpIchol: return "pcg_warp_ichol";
    case SolverKind::kCompliance: return "compliance";
  }
  return "?";
}

SolverKind SolverKindFromString(const std::string& name) {
  for (SolverKind k : {SolverKind::kCholmod, SolverKind::kLdlt, SolverKind::kPcgJacobi, SolverKind::kPcgWarp,
                       SolverKind::kPcgWarpLdlt, SolverKind::kPcgWarpIchol, SolverKind::kCompliance})
    if (name == ToString(k)) return k;
  throw std::invalid_argument("unknown solver type '" + name + "'");
}

SceneDescription ReadSceneDescription(const std::string& path) { return Parse(config::LoadYamlFile(path)); }

SceneDescription ParseSceneDescription(const std::string& text, const std::string& file) {
  return Parse(config::LoadYamlString(text, file));
}

std::vector<std::string> PresetNames() { return {"fast", "balanced", "accurate"}; }

void ApplyPreset(const std::string& name, SceneDescription& s) {
  // Chosen from the measured accuracy-cost study (docs/accuracy-cost.md).
  // Each preset picks its element: the nodal pressure tet is only ever asked for by name.
  if (name == "fast") {
    s.nodal_pressure = false;
    s.elasticity = fem::ElasticFormulation::kLinear;
    // Without contact the matrix is constant: factorized once, one back-substitution a
    // step (CHOLMOD's is ~3x faster than the LDL^T's on B). Contact changes it every
    // step; refactorizing (~11 ms on model B) still costs more than the PCG preconditioned
    // by the rest factor, which is exact without contact and close with it.
    s.solver = s.contact ? SolverKind::kPcgWarp : SolverKind::kCholmod;
    s.integrator.newton_iterations = 1;
  } else if (name == "balanced") {
    s.nodal_pressure = false;
    s.elasticity = fem::ElasticFormulation::kCorotational;
    s.solver = SolverKind::kPcgWarp;
    s.pcg.relative_tolerance = 1e-4;
    s.pcg.max_iterations = 50;
    s.integrator.newton_iterations = 1;
  } else if (name == "accurate") {
    s.nodal_pressure = false;
    s.elasticity = fem::ElasticFormulation::kCorotational;
    s.solver = SolverKind::kCholmod;  // refactorized every Newton iteration: ~7x faster than LDL^T on B
    s.integrator.newton_iterations = 3;
  } else {
    throw std::invalid_argument("unknown preset '" + name + "' (fast, balanced, accurate)");
  }
}

}  // namespace sedbridge::scene
