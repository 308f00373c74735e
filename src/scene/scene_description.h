#pragma once
// A scene YAML (config/scenes/*.yaml) says which model to load and which effects to
// simulate. Absent sections are not built and cost nothing. Every key is documented in
// config/scenes/README.md; unknown keys are errors naming file:line:column.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/enum_names.h"
#include "common/name_value.h"
#include "fem/bone_coupling_force.h"
#include "fem/elastic_tet_force.h"
#include "fem/linear_solver.h"
#include "fem/penalty_contact_force.h"
#include "fem/simulation.h"
#include "common/geometry/rigid_object.h"
#include "display/display_profile.h"
#include "scene/merkel_side.h"

namespace sedbridge::scene {

/// Most `dynamics.steps` a scene may ask for: 1e6 steps of the fast preset is already hours;
/// 2e9 ran until killed.
inline constexpr int kMaxSceneSteps = 1000000;

/// Named solver presets (docs/accuracy-cost.md): `preset:` in scene and bridge YAML.
enum class Preset { kFast, kBalanced, kAccurate };
/// "fast", "balanced", "accurate": the one list of preset names. Inline (and PresetNames):
/// the YAML fuzzer links the bridge config reader without the scene stage.
inline const config::EnumNames<Preset>& NamesOf(Preset) {
  static const config::EnumNames<Preset> names{
      {Preset::kFast, "fast"}, {Preset::kBalanced, "balanced"}, {Preset::kAccurate, "accurate"}};
  return names;
}

/// The scene key `elasticity`: the element formulation, one name for two members.
enum class SceneElasticity { kCorotational, kLinear, kNodalPressure };
/// "corotational", "linear", "nodal_pressure".
const config::EnumNames<SceneElasticity>& NamesOf(SceneElasticity);

/// Fields are named in each Serialize (common/name_value.h): key, unit, allowed range; the
/// member initialisers are the defaults. scene_description.cpp reads them.
struct BoneSection {
  fem::SpringDamperParams spring;   ///< paper: k 200 N/m, b 0.1 N s/m, a 1.0
  /// Tracked bone pose (model frame, relative to rest); null = fixed. Keys `mode`
  /// (fixed | tracked) and `motion` are read by scene_description.cpp.
  std::shared_ptr<const geometry::Trajectory> motion;

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("stiffness_N_m", &spring.stiffness_N_m).Positive());
    a->Visit(Field("damping_N_s_m", &spring.damping_N_s_m).NonNegative());
    a->Visit(Field("anisotropy", &spring.anisotropy).NonNegative());
    a->HandRead("mode");
    a->HandRead("motion");
  }
};

struct ContactSection {
  fem::ContactParams params;                 ///< paper: k 1e4 N/m, b 0.5 N s/m
  /// Poses in the pad frame; key `objects` (required, not empty) is read by
  /// scene_description.cpp (geometry::ParseRigidObjects).
  std::vector<geometry::RigidObject> objects_pad_frame;

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("stiffness_N_m", &params.stiffness_N_m).Positive());
    a->Visit(Field("damping_N_s_m", &params.damping_N_s_m).NonNegative());
    a->HandRead("objects");
  }
};

struct FrictionSection {
  double anisotropy = 0.0;  ///< tangential stiffness factor a (0 = frictionless: not built)
  double coulomb_mu = 0.0;  ///< sliding limit, 0 = sticking springs only

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(config::Field("anisotropy", &anisotropy).NonNegative());
    a->Visit(config::Field("coulomb_mu", &coulomb_mu).NonNegative());
  }
};

struct OutputSection {
  bool merkel_sed = true;   ///< SED on the Merkel layer every step
  bool full_sed = false;    ///< SED on every node (VTU); costs a full element pass
  int vtu_every = 0;        ///< write a VTU frame every N steps (0 = none)
  /// Merkel vertex value: averaged over both sides of the interface, or one (merkel_side.h).
  MerkelSide merkel_side = MerkelSide::kBoth;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(config::Field("merkel_sed", &merkel_sed));
    a->Visit(config::Field("merkel_side", &merkel_side));
    a->Visit(config::Field("full_sed", &full_sed));
    a->Visit(config::Field("vtu_every", &vtu_every).NonNegative());
  }
};

/// Scene key `display`: a press by a display worn on the finger instead of a contact
/// object — its actuators at `commands` on the pad resting on it (render/display_press.h):
/// "what does this command do to the finger?". Read and checked by scene_description.cpp:
/// the profile loads, one command per actuator, each in [0, the actuator's safety maximum].
struct DisplayLoadSection {
  display::DisplayProfile profile;  ///< key `profile`: a shipped name or a path
  std::vector<double> commands;     ///< key `commands`: one per actuator [the profile's unit]
};

/// Scene `solver.type`.
enum class SolverKind {
  kCholmod,       ///< "cholmod": supernodal Cholesky (the default)
  kLdlt,          ///< "ldlt": Eigen's simplicial LDL^T
  kPcgJacobi,     ///< "pcg_jacobi"
  kPcgWarp,       ///< "pcg_warp": warped rest factor by CHOLMOD
  kPcgWarpLdlt,   ///< "pcg_warp_ldlt": warped rest factor by LDL^T
  kPcgWarpIchol,  ///< "pcg_warp_ichol": warped incomplete Cholesky
  kCompliance,    ///< "compliance": contact by the compliance method (scene/fingertip_compliance.h),
                  ///< linear quasi-static scenes with the bone fixed only
};
/// "ldlt", "cholmod", "pcg_jacobi", "pcg_warp", "pcg_warp_ldlt", "pcg_warp_ichol" (the
/// names of fem::LinearSolverKind, which fem::MakeLinearSolver takes) and "compliance".
const config::EnumNames<SolverKind>& NamesOf(SolverKind);
/// The config name (NamesOf).
const char* ToString(SolverKind kind);
/// The kind named by `name`; throws std::invalid_argument for others.
SolverKind SolverKindFromString(const std::string& name);

struct SceneDescription {
  std::string file;          ///< where it was read from
  std::string model;         ///< model name or path (LoadFingertipModel)
  std::string preset;        ///< preset name it started from, if any
  fem::ElasticFormulation elasticity = fem::ElasticFormulation::kCorotational;
  /// `elasticity: nodal_pressure`: corotational with the average nodal pressure tet
  /// (fem/nodal_pressure_tet_force.h): no volumetric locking at nu = 0.48.
  bool nodal_pressure = false;
  fem::IntegratorSettings integrator;
  double dt_s = 1e-3;        ///< backward Euler step; quasi-static: load increment 1/steps
  int steps = 50;            ///< number of steps the scene runs, in [1, kMaxSceneSteps]
  /// `solver.type`: a linear solver of the simulation, or the compliance method.
  SolverKind solver = SolverKind::kCholmod;
  std::string solver_cache_dir;  ///< compliance: precompute cache folder ("" = none)
  fem::PcgSettings pcg;
  double rayleigh_beta_s = 0.0;
  std::optional<BoneSection> bone;          ///< absent: the soft tissue floats (rarely wanted)
  std::optional<ContactSection> contact;
  std::optional<FrictionSection> friction;  ///< needs contact
  bool surface_traction = false;            ///< the bridge's sensor-driven load
  /// A display press (no `contact`; solver.type compliance, as the display rendering's).
  std::optional<DisplayLoadSection> display;
  OutputSection outputs;

  SceneElasticity elasticity_name() const;
  void set_elasticity(SceneElasticity e);

  /// Every key of a scene YAML. `preset` is applied before the other keys (they override
  /// it); `bone` and `contact` have hand-read keys (see their structs).
  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("model", &model).Required());
    a->Visit(Field("preset", &preset));  // checked by ApplyPreset
    SceneElasticity e = elasticity_name();
    a->Visit(Field("elasticity", &e));
    set_elasticity(e);
    a->Section("dynamics", [&](auto* d) {
      d->Visit(Field("integrator", &integrator.kind));
      d->Visit(Field("dt_s", &dt_s).Positive());
      d->Visit(Field("steps", &steps).InRange(1, kMaxSceneSteps));
      d->Visit(Field("newton_iterations", &integrator.newton_iterations).AtLeast(1));
      d->Visit(Field("newton_tolerance_mm", &integrator.newton_tolerance_m).Positive().Scale(1e-3));
      d->Visit(Field("rayleigh_alpha_1_s", &integrator.rayleigh_alpha_1_s).NonNegative());
      d->Visit(Field("extrapolate_warm_start", &integrator.extrapolate_warm_start));
      d->Visit(Field("rayleigh_beta_s", &rayleigh_beta_s).NonNegative());
    });
    a->Section("solver", [&](auto* so) {
      so->Visit(Field("type", &solver));
      so->Visit(Field("cache_dir", &solver_cache_dir));  // compliance only: checked after reading
      so->Visit(Field("tolerance", &pcg.relative_tolerance).Positive());
      so->Visit(Field("max_iterations", &pcg.max_iterations).AtLeast(1));
      so->Visit(Field("fallback_to_direct", &pcg.fallback_to_direct));
      so->Visit(Field("contact_update", &pcg.stiff_node_update));  // warped PCG: contact springs in the preconditioner
      so->Visit(Field("single_precision_factor", &pcg.single_precision_factor));  // pcg_warp: float copy of the rest factor
      so->Visit(Field("matrix_free", &pcg.matrix_free));  // PCG without fallback: element products, no element blocks
    });
    a->Visit(Field("bone", &bone));        // absent: the soft tissue floats
    a->Visit(Field("contact", &contact));  // absent: no contact term
    a->Visit(Field("friction", &friction));  // needs contact; a = 0 is dropped after reading
    a->Visit(Field("surface_traction", &surface_traction));
    a->HandRead("display");  // profile, commands: scene_description.cpp
    a->Visit(Field("outputs", &outputs));
  }
};

/// Reads a scene file. Throws config::ConfigError (file:line:column) on any error.
SceneDescription ReadSceneDescription(const std::string& path);
/// Same from text (tests).
SceneDescription ParseSceneDescription(const std::string& yaml_text, const std::string& file);

/// Applies a named preset ("fast", "balanced", "accurate": docs/accuracy-cost.md) to
/// the solver-related fields. `fast` picks a Cholesky (CHOLMOD) factorized once for a scene without
/// contact and pcg_warp with it (contact changes the matrix every step), so apply it after
/// `scene.contact` is set (ReadSceneDescription does; an explicit `solver.type` wins).
/// Throws std::invalid_argument "unknown preset 'x' (fast, balanced, accurate)".
void ApplyPreset(const std::string& name, SceneDescription& scene);
/// Every preset name (NamesOf(Preset)).
inline std::vector<std::string> PresetNames() { return config::AllNames<Preset>(); }

}  // namespace sedbridge::scene
