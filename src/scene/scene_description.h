#pragma once
// A scene YAML (config/scenes/*.yaml) says which model to load and which effects to
// simulate. Absent sections are not built and cost nothing. Every key is documented in
// config/scenes/README.md; unknown keys are errors naming file:line:column.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fem/bone_coupling_force.h"
#include "fem/elastic_tet_force.h"
#include "fem/linear_solver.h"
#include "fem/penalty_contact_force.h"
#include "fem/simulation.h"
#include "common/geometry/rigid_object.h"

namespace sedbridge::scene {

/// Most `dynamics.steps` a scene may ask for: 1e6 steps of the fast preset is already hours;
/// 2e9 ran until killed.
inline constexpr int kMaxSceneSteps = 1000000;

struct BoneSection {
  fem::SpringDamperParams spring;   ///< paper: k 200 N/m, b 0.1 N s/m, a 1.0
  /// Tracked bone pose (model frame, relative to rest); null = fixed.
  std::shared_ptr<const geometry::Trajectory> motion;
};

struct ContactSection {
  fem::ContactParams params;                 ///< paper: k 1e4 N/m, b 0.5 N s/m
  std::vector<geometry::RigidObject> objects_pad_frame;  ///< poses in the pad frame
};

struct FrictionSection {
  double anisotropy = 0.0;  ///< tangential stiffness factor a (0 = frictionless: not built)
  double coulomb_mu = 0.0;  ///< sliding limit, 0 = sticking springs only
};

struct OutputSection {
  bool merkel_sed = true;   ///< SED on the Merkel layer every step
  bool full_sed = false;    ///< SED on every node (VTU); costs a full element pass
  int vtu_every = 0;        ///< write a VTU frame every N steps (0 = none)
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
/// The config name, which is also fem::MakeLinearSolver's name for the linear solvers.
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
  OutputSection outputs;
};

/// Reads a scene file. Throws config::ConfigError (file:line:column) on any error.
SceneDescription ReadSceneDescription(const std::string& path);
/// Same from text (tests).
SceneDescription ParseSceneDescription(const std::string& yaml_text, const std::string& file);

/// Applies a named preset ("fast", "balanced", "accurate": docs/accuracy-cost.md) to
/// the solver-related fields. `fast` picks a Cholesky (CHOLMOD) factorized once for a scene without
/// contact and pcg_warp with it (contact changes the matrix every step), so apply it after
/// `scene.contact` is set (ReadSceneDescription does; an explicit `solver.type` wins).
/// Throws std::invalid_argument for an unknown name.
void ApplyPreset(const std::string& name, SceneDescription& scene);
std::vector<std::string> PresetNames();

}  // namespace sedbridge::scene
