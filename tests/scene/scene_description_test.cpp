#include "scene/scene_description.h"

#include <gtest/gtest.h>

#include "common/config_error.h"
#include "common/resource_path.h"
#include "common/schema_keys.h"
#include "tests/common/readme_keys.h"

namespace sedbridge::scene {
namespace {

TEST(SceneDescription, ShippedPaperPressParses) {
  const SceneDescription s = ReadSceneDescription(config::ResolveResource("config/scenes/paper_press.yaml"));
  EXPECT_EQ(s.model, "B");
  EXPECT_EQ(s.integrator.kind, fem::IntegratorKind::kQuasiStatic);
  EXPECT_EQ(s.steps, 50);
  EXPECT_DOUBLE_EQ(s.dt_s, 1.0 / 50);
  ASSERT_TRUE(s.bone.has_value());
  EXPECT_DOUBLE_EQ(s.bone->spring.stiffness_N_m, 200);
  ASSERT_TRUE(s.contact.has_value());
  EXPECT_DOUBLE_EQ(s.contact->params.stiffness_N_m, 1e4);
  EXPECT_FALSE(s.friction.has_value());  // frictionless: not built
  EXPECT_FALSE(s.surface_traction);
}

TEST(SceneDescription, MinimalSceneBuildsNothingExtra) {
  const SceneDescription s = ParseSceneDescription("model: B\n", "min.yaml");
  EXPECT_FALSE(s.bone || s.contact || s.friction || s.surface_traction);
}

TEST(SceneDescription, ZeroFrictionIsNotBuilt) {
  const SceneDescription s = ParseSceneDescription(
      "model: B\ncontact:\n  objects: [{shape: plane}]\nfriction: {anisotropy: 0.0}\n", "f.yaml");
  EXPECT_FALSE(s.friction.has_value());
}

void ExpectErrorAt(const std::string& yaml, int line, const std::string& words) {
  try {
    ParseSceneDescription(yaml, "bad.yaml");
    FAIL() << "accepted: " << yaml;
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.where().line, line) << e.what();
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(SceneDescription, ErrorsNameTheLine) {
  ExpectErrorAt("model: B\ndynamics:\n  integrator: rk4\n", 3, "must be one of");
  ExpectErrorAt("model: B\ndynamics:\n  dt_s: -1\n", 3, "> 0");
  ExpectErrorAt("model: B\nsolver:\n  tolerence: 1e-6\n", 3, "unknown key 'tolerence'");
  ExpectErrorAt("model: B\nfriction: {anisotropy: 0.5}\n", 2, "needs a 'contact'");
  ExpectErrorAt("model: B\npreset: turbo\n", 2, "unknown preset");
  ExpectErrorAt("dynamics: {steps: 3}\n", 1, "missing required key 'model'");
  ExpectErrorAt("model: B\nbone: {mode: fixed, motion: {}}\n", 2, "needs mode: tracked");
}

// A display press: `display: {profile, commands}`, the compliance method, no contact object.
constexpr const char* kDisplayScene =
    "model: B\n"
    "elasticity: linear\n"
    "dynamics: {integrator: quasi_static, steps: 1}\n"
    "solver: {type: compliance}\n"
    "bone: {mode: fixed}\n";

TEST(SceneDescription, DisplayPressReadsTheProfileAndOneCommandPerActuator) {
  const SceneDescription s = ParseSceneDescription(
      std::string(kDisplayScene) + "display:\n  profile: suction_4x4\n  commands: [0, 0, 0, 0, 0, 10, 10, 0, 0, 10, 10, 0, 0, 0, 0, 20]\n",
      "d.yaml");
  ASSERT_TRUE(s.display.has_value());
  EXPECT_EQ(s.display->profile.name, "suction_4x4");
  ASSERT_EQ(s.display->commands.size(), 16u);
  EXPECT_EQ(s.display->commands[5], 10.0);
  EXPECT_EQ(s.display->commands[15], 20.0);  // safety.max: the most that reaches the finger
  EXPECT_FALSE(s.contact.has_value());

  const SceneDescription shipped =
      ReadSceneDescription(config::ResolveResource("config/scenes/display_suction_press.yaml"));
  ASSERT_TRUE(shipped.display.has_value());
  EXPECT_EQ(shipped.display->profile.name, "suction_4x4");
  EXPECT_EQ(shipped.display->commands.size(), shipped.display->profile.size());
}

TEST(SceneDescription, DisplayPressErrorsNameTheLineAndColumn) {
  const std::string scene = kDisplayScene;
  // Wrong length: at the list.
  ExpectErrorAt(scene + "display:\n  profile: suction_4x4\n  commands: [1, 2, 3]\n", 8,
                "'commands' has 3 entries; suction_4x4 has 16 actuators");
  // Out of range: at the entry (column of the fourth value).
  try {
    ParseSceneDescription(scene + "display:\n  profile: pin_6x4\n  commands: [0, 0, 0, 1.6" +
                              ", 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]\n",
                          "bad.yaml");
    FAIL() << "accepted a pin above its safety maximum";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.where().line, 8) << e.what();
    EXPECT_EQ(e.where().column, 23) << e.what();  // the 1.6
    EXPECT_NE(std::string(e.what()).find("command 3 (1.6 mm) is outside [0, 1.5] mm"), std::string::npos) << e.what();
  }
  ExpectErrorAt(scene + "display:\n  profile: suction_4x4\n  commands: [-1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]\n", 8,
                "command 0 (-1 kPa) is outside [0, 20] kPa");
  ExpectErrorAt(scene + "display:\n  profile: suction_5x5\n  commands: [0]\n", 7, "display profile 'suction_5x5'");
  ExpectErrorAt(scene + "display:\n  profile: electrotactile_4x4\n  commands: [0]\n", 7,
                "no mechanical load on the finger to press (electrotactile");
  ExpectErrorAt(scene + "display:\n  profile: suction_4x4\n  commands: [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]\n"
                        "  gain: 2\n",
                9, "unknown key 'gain'");
  // One load at a time, solved as the display rendering is.
  ExpectErrorAt(scene + "contact: {objects: [{shape: plane}]}\n"
                        "display: {profile: suction_4x4, commands: [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]}\n",
                7, "two loads");
  ExpectErrorAt("model: B\ndisplay: {profile: suction_4x4, commands: [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]}\n", 2,
                "solver.type: compliance");
}

TEST(SceneDescription, PresetThenExplicitKeysOverride) {
  const SceneDescription s = ParseSceneDescription("model: B\npreset: fast\nsolver: {type: pcg_jacobi}\n", "p.yaml");
  EXPECT_EQ(s.elasticity, fem::ElasticFormulation::kLinear);
  EXPECT_EQ(s.solver, SolverKind::kPcgJacobi);
}

TEST(SceneDescription, FastPresetFactorizesOnceWithoutContactAndPreconditionsWithContact) {
  const std::string contact =
      "contact:\n  objects:\n    - {name: plane, shape: plane, rpy_deg: [180, 0, 0], position_mm: [0, 0, 0]}\n";
  const SceneDescription traction = ParseSceneDescription("model: B\npreset: fast\nsurface_traction: true\n", "t.yaml");
  EXPECT_EQ(traction.solver, SolverKind::kCholmod);  // constant matrix: one factorization for the whole run
  const SceneDescription press = ParseSceneDescription("model: B\npreset: fast\n" + contact, "c.yaml");
  EXPECT_EQ(press.elasticity, fem::ElasticFormulation::kLinear);
  EXPECT_EQ(press.solver, SolverKind::kPcgWarp);  // contact would refactorize LDL^T every step
  const SceneDescription forced =
      ParseSceneDescription("model: B\npreset: fast\nsolver: {type: ldlt}\n" + contact, "f.yaml");
  EXPECT_EQ(forced.solver, SolverKind::kLdlt);  // an explicit choice wins
  // Applied after reading (sedbridge press --preset fast on a contact scene).
  SceneDescription cli = ParseSceneDescription("model: B\n" + contact, "cli.yaml");
  ApplyPreset("fast", cli);
  EXPECT_EQ(cli.solver, SolverKind::kPcgWarp);
}

// `press --preset fast` on a quasi-static contact press with the bone fixed uses
// the compliance method; where the method cannot answer (full_sed, a dynamic scene) the
// fast preset keeps the FE step.
TEST(SceneDescription, FastPresetUsesTheComplianceMethodForAQuasiStaticPress) {
  const std::string press =
      "model: B\ndynamics: {integrator: quasi_static, steps: 5}\nbone: {mode: fixed}\n"
      "contact:\n  objects:\n    - {name: plane, shape: plane, rpy_deg: [180, 0, 0], position_mm: [0, 0, 0]}\n";
  SceneDescription cli = ParseSceneDescription(press, "q.yaml");
  ApplyPreset("fast", cli);
  EXPECT_EQ(cli.solver, SolverKind::kCompliance);
  EXPECT_EQ(ParseSceneDescription("preset: fast\n" + press, "f.yaml").solver, SolverKind::kCompliance);
  SceneDescription full = ParseSceneDescription(press + "outputs: {full_sed: true}\n", "s.yaml");
  ApplyPreset("fast", full);
  EXPECT_EQ(full.solver, SolverKind::kPcgWarp);
  SceneDescription dynamic = ParseSceneDescription(
      "model: B\nbone: {mode: fixed}\ncontact:\n  objects:\n    - {name: plane, shape: plane, rpy_deg: [180, 0, 0]}\n",
      "d.yaml");
  ApplyPreset("fast", dynamic);
  EXPECT_EQ(dynamic.solver, SolverKind::kPcgWarp);
}


TEST(SceneDescription, StepCountAndKeyframesAreBounded) {
  // Hostile inputs: 2e9 steps ran until killed; a .nan keyframe ran with d = nan and exited 0.
  EXPECT_THROW(ParseSceneDescription("model: B\ndynamics: {steps: 2000000000}\n", "s.yaml"), config::ConfigError);
  EXPECT_NO_THROW(ParseSceneDescription("model: B\ndynamics: {steps: 1000000}\n", "s.yaml"));
  const std::string nan_key =
      "model: B\ncontact:\n  objects:\n    - name: plane\n      shape: plane\n      rpy_deg: [180, 0, 0]\n"
      "      motion:\n        keyframes:\n          - {t_s: 0}\n          - {t_s: 1, offset_mm: [0, 0, .nan]}\n";
  try {
    ParseSceneDescription(nan_key, "k.yaml");
    FAIL() << "NaN keyframe accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("finite"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sedbridge::scene

namespace sedbridge::scene {
namespace {

TEST(SceneDescription, NodalPressureIsOneMoreElasticityValue) {
  const SceneDescription s = ParseSceneDescription("model: B\nelasticity: nodal_pressure\n", "n.yaml");
  EXPECT_TRUE(s.nodal_pressure);
  EXPECT_EQ(s.elasticity, fem::ElasticFormulation::kCorotational);  // ANP is corotational
  EXPECT_FALSE(ParseSceneDescription("model: B\nelasticity: corotational\n", "c.yaml").nodal_pressure);
  EXPECT_FALSE(ParseSceneDescription("model: B\n", "d.yaml").nodal_pressure);
  // A preset picks its own element (as `sedbridge press --preset` applies it after the file).
  SceneDescription p = s;
  ApplyPreset("balanced", p);
  EXPECT_FALSE(p.nodal_pressure);
  const SceneDescription shipped =
      ReadSceneDescription(config::ResolveResource("config/scenes/paper_press_nodal_pressure.yaml"));
  EXPECT_TRUE(shipped.nodal_pressure);
}

}  // namespace
}  // namespace sedbridge::scene

// The key table of config/scenes/README.md and the scene schema name the same keys.
namespace sedbridge::scene {
namespace {

TEST(SceneDescription, ReadmeTableNamesEverySchemaKeyAndNoOther) {
  test_util::ExpectReadmeNamesSchemaKeys(config::ResolveResource("config/scenes/README.md"), config::SchemaKeys<SceneDescription>());
}

}  // namespace
TEST(SceneDescription, SolverTypesAreTheLinearSolversAndCompliance) {
  // fem::MakeLinearSolver is handed ToString(solver): the two tables must agree.
  std::vector<std::string> scene_names = config::AllNames<SolverKind>();
  ASSERT_EQ(scene_names.back(), "compliance");
  scene_names.pop_back();
  EXPECT_EQ(scene_names, fem::LinearSolverNames());
}

}  // namespace sedbridge::scene
