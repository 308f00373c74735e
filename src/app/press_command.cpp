// sedbridge press: the paper's experiment (Sec. IV-A) on a fingertip model.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "app/arg_parser.h"
#include "app/command.h"
#include "app/plot_runner.h"
#include "common/resource_path.h"
#include "model/fingertip_model.h"
#include "render/display_on_leader.h"
#include "render/display_press.h"
#include "scene/fingertip_compliance.h"
#include "scene/press_experiment.h"

namespace sedbridge::app {
namespace {

// A scene with `display`: the display's commands on the leader's pad, one full contact
// answer (render/display_press.h), instead of a contact object pushed in steps.
int RunDisplayPress(const scene::SceneDescription& scene, const std::string& out, bool plots) {
  const auto t_load = std::chrono::steady_clock::now();
  const scene::DisplayLoadSection& load = *scene.display;
  const model::FingertipModel model = model::LoadFingertipModel(scene.model);
  scene::FingertipCompliance leader(model, render::DisplayLeaderOptions(scene::ComplianceOptionsFromScene(scene)));
  std::printf("model %s: %d soft nodes, %zu Merkel vertices; display %s (%s, %zu actuators, %s) from %s\n",
              model.name.c_str(), model.num_soft_nodes(), model.merkel_nodes.size(), load.profile.name.c_str(),
              display::ToString(load.profile.kind).c_str(), load.profile.size(), load.profile.unit.c_str(),
              load.profile.file.c_str());
  const Eigen::VectorXd commands =
      Eigen::Map<const Eigen::VectorXd>(load.commands.data(), Eigen::Index(load.commands.size()));
  const render::DisplayPressResult r = render::PressDisplay(leader, load.profile, commands);
  render::WriteDisplayPress(leader, load.profile, commands, r, out);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_load).count();
  std::printf("preload %.3f N (%.1f kPa over the actuated area); max Merkel SED %.1f Pa at rest on the display, "
              "%.1f Pa with the commands (%.1f Pa added at most)\n",
              r.preload_force_N, load.profile.device.preload_kPa, r.preload_sed_Pa.maxCoeff(), r.sed_Pa.maxCoeff(),
              (r.sed_Pa - r.preload_sed_Pa).maxCoeff());
  std::printf("done in %.1f s\n", seconds);
  if (plots) std::printf("plots: none for a display press (merkel_sed.csv, display_press.vtu)\n");
  std::printf("results: %s\n", out.c_str());
  return 0;
}

int RunPress(int argc, char** argv) {
  ArgParser args("sedbridge press",
                 "Presses a rigid plane 2.0 mm into the pad of a fingertip model tilted 15 deg, as in\n"
                 "the paper's validation (Sec. IV-A), and writes force, contact area and the SED at\n"
                 "the Merkel layer (epidermis-dermis interface) at the step closest to 1.0 N.");
  args.Option("model", "A|B|C|NAME|PATH", "model name (config/models/NAME.yaml), model YAML or .msh", "scene's")
      .Option("scene", "FILE", "scene YAML", "config/scenes/paper_press.yaml")
      .Option("preset", "NAME", "solver preset: fast, balanced or accurate (overrides the scene's solver)")
      .Option("out", "DIR", "output folder", "out/press")
      .Option("target-force", "N", "force at which the SED map and path are taken", "1.0")
      .Flag("no-plots", "write CSV and VTU only")
      .Flag("quiet", "no per-step progress")
      .Epilog(
          "outputs in DIR:\n"
          "  force_displacement.csv  step,displacement_mm,force_N,contact_area_mm2 (one row per step)\n"
          "  merkel_sed.csv          vertex,x_mm,y_mm,z_mm,sed_Pa at the step closest to the target force\n"
          "                          (pad frame; vertex = Gmsh node tag)\n"
          "  sed_path.csv            x_mm,sed_Pa,sed_normalized along x at y = 2 mm\n"
          "  step_timing.csv         per step: wall_ms, Newton and linear iterations, and threads\n"
          "                          (the OpenMP team it ran on: its own choice unless\n"
          "                          OMP_NUM_THREADS is set)\n"
          "  frames.pvd + frame_*.vtu  deformation and SED for ParaView\n"
          "  *.png                   force-displacement, area-force, Merkel SED map, SED path plots\n"
          "a scene with `display: {profile, commands}` (config/scenes/display_suction_press.yaml) presses\n"
          "the display's commands on the pad resting on it instead, by full contact, and writes\n"
          "merkel_sed.csv, display_added_sed.csv, display_commands.csv, display_press.csv and\n"
          "display_press.vtu (render/display_press.h)\n\n"
          "example:\n  sedbridge press --model B --out out/press_B");
  if (!args.Parse(argc, argv)) return 0;

  scene::SceneDescription scene = scene::ReadSceneDescription(config::ResolveResource(args.Get("scene")));
  if (args.Has("model")) scene.model = args.Get("model");
  if (args.Has("preset")) {
    scene::ApplyPreset(args.Get("preset"), scene);
    // Say why a fast quasi-static press does not get the compliance method.
    if (args.Get("preset") == "fast" && scene.contact && scene.solver != scene::SolverKind::kCompliance &&
        scene.integrator.kind == fem::IntegratorKind::kQuasiStatic) {
      scene::SceneDescription trial = scene;
      trial.solver = scene::SolverKind::kCompliance;
      try {
        scene::ComplianceOptionsFromScene(trial);
      } catch (const std::invalid_argument& e) {
        std::fprintf(stderr, "note: preset fast: not the compliance method here (%s)\n", e.what());
      }
    }
  }
  const std::string out = args.Get("out");
  std::filesystem::create_directories(out);
  if (scene.display) return RunDisplayPress(scene, out, !args.GetFlag("no-plots"));

  const auto t_load = std::chrono::steady_clock::now();
  scene::FingertipScene fingertip(scene);
  const auto& m = fingertip.model();
  std::printf("model %s: %d soft nodes, %d soft tets, %zu Merkel vertices, %zu bone-attached nodes\n",
              m.name.c_str(), m.num_soft_nodes(), m.soft.num_tets(), m.merkel_nodes.size(), m.attached_nodes.size());
  std::string effects;
  for (const auto& e : fingertip.BuiltEffects()) effects += (effects.empty() ? "" : ", ") + e;
  // The compliance method answers the contact from its precompute: the simulation's own
  // solver (it factorized K for that) never steps.
  const std::string solver = fingertip.compliance()
                                 ? "compliance (contact on the pad's precomputed compliance, " +
                                       std::to_string(fingertip.compliance()->contact().candidate_nodes().size()) +
                                       " candidate nodes)"
                                 : fingertip.simulation().solver().name();
  std::printf("effects: %s; solver %s; %d steps\n", effects.c_str(), solver.c_str(), scene.steps);

  scene::PressOptions options;
  options.target_force_N = args.GetDouble("target-force");
  options.vtu_dir = out;
  const bool quiet = args.GetFlag("quiet");
  int warnings = 0;
  options.on_step = [&](const scene::PressStepRecord& r) {
    if (!r.report.converged || r.report.inverted_elements > 0) ++warnings;
    if (quiet) return;
    std::printf("  step %3d/%d  d = %5.2f mm  F = %6.3f N  area = %6.1f mm2  max SED = %8.1f Pa  newton %2d%s%s  %6.1f ms\n",
                r.step, scene.steps, r.displacement_mm, r.force_N, r.contact_area_mm2, r.max_merkel_sed_Pa,
                r.report.newton_iterations, r.report.converged ? "" : " (not converged)",
                r.report.inverted_elements ? " (inverted elements)" : "", r.wall_ms);
    std::fflush(stdout);
  };
  const scene::PressResult result = scene::RunPress(fingertip, options);
  scene::WritePressCsv(fingertip, result, out);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_load).count();

  const auto& sel = result.steps[size_t(result.selected)];
  std::printf("\nforce at %.2f mm: %.3f N; contact area %.1f mm2\n", result.steps.back().displacement_mm,
              result.steps.back().force_N, result.steps.back().contact_area_mm2);
  std::printf("closest to %.2f N: step %d (d = %.2f mm, F = %.3f N); max Merkel SED %.1f Pa\n", options.target_force_N,
              sel.step, sel.displacement_mm, sel.force_N, result.selected_max_sed_Pa);
  if (std::abs(sel.force_N - options.target_force_N) > 0.05 * options.target_force_N)
    std::printf("warning: the force never came within 5 %% of %.2f N; the SED map and path are at step %d (%.3f N)\n",
                options.target_force_N, sel.step, sel.force_N);
  if (warnings) std::printf("warning: %d steps did not converge or had inverted elements (see progress)\n", warnings);
  std::printf("done in %.1f s\n", seconds);
  if (!args.GetFlag("no-plots")) {
    if (RunPlotScript("plot_press.py", {out, "--out", out})) std::printf("plots: %s/*.png\n", out.c_str());
  }
  // frames.pvd exists only when the scene writes VTU frames (outputs.vtu_every > 0).
  if (fingertip.description().outputs.vtu_every > 0)
    std::printf("results: %s (open %s/frames.pvd in ParaView)\n", out.c_str(), out.c_str());
  else
    std::printf("results: %s\n", out.c_str());
  return 0;
}

}  // namespace

SEDBRIDGE_COMMAND(press, "press", "the paper's press experiment: force, contact area, Merkel SED", &RunPress);

}  // namespace sedbridge::app
