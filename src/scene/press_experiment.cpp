#include "scene/press_experiment.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <stdexcept>

#include "fem/thread_team.h"
#include "scene/vtu_writer.h"

namespace sedbridge::scene {

PressResult RunPress(FingertipScene& scene, const PressOptions& options) {
  if (!scene.contact()) throw std::invalid_argument("the press needs a scene with a contact object");
  if (!scene.merkel()) throw std::invalid_argument("the press needs outputs.merkel_sed: true");
  PressResult result;
  const auto& object = scene.contact()->objects().front();
  const Eigen::Vector3d start = object.trajectory.Pose(0.0).translation();
  const int steps = scene.description().steps;
  const int vtu_every = scene.description().outputs.vtu_every;
  std::unique_ptr<PvdCollection> pvd;
  std::unique_ptr<fem::VertexSedEvaluator> full_sed;
  const bool quasi_static = scene.description().integrator.kind == fem::IntegratorKind::kQuasiStatic;
  if (!options.vtu_dir.empty() && vtu_every > 0) {
    std::filesystem::create_directories(options.vtu_dir);
    // Quasi-static steps have no physical time: ParaView's "Time" is then the plate's
    // displacement, the load parameter a reader of the force-displacement curve knows.
    pvd = std::make_unique<PvdCollection>(options.vtu_dir + "/frames.pvd",
                                          quasi_static ? "plate displacement [mm] (quasi-static: a load parameter, not time)"
                                                       : "simulated time [s]");
    if (scene.description().outputs.full_sed) {
      std::vector<int> all(size_t(scene.model().num_soft_nodes()));
      for (size_t i = 0; i < all.size(); ++i) all[i] = int(i);
      full_sed = std::make_unique<fem::VertexSedEvaluator>(scene.elastic(), all, scene.nodal_pressure());
    }
  }
  for (int k = 1; k <= steps; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    PressStepRecord rec;
    rec.report = scene.Step();
    rec.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    rec.step = k;
    rec.t_s = scene.time_s();
    if (!scene.compliance()) scene.simulation().TotalForce();  // contact set at the converged state
    rec.displacement_mm = (object.trajectory.Pose(rec.t_s).translation() - start).norm() * 1e3;
    rec.force_N = scene.ContactSpringForce_N().norm();
    rec.contact_area_mm2 = scene.ContactArea_m2() * 1e6;
    rec.max_merkel_sed_Pa = scene.merkel()->sed_Pa().size() ? scene.merkel()->sed_Pa().maxCoeff() : 0.0;
    result.merkel_sed.push_back(scene.merkel()->sed_Pa());
    result.steps.push_back(rec);
    if (pvd && (k % vtu_every == 0 || k == steps)) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%04d.vtu", k);
      std::vector<VtuField> point_fields;
      if (full_sed) {
        Eigen::VectorXd sed;
        // A whole element pass: on the step's team (all cores of a 16-core machine cost
        // more than they bring, docs/performance.md), not measured as part of the step.
        const fem::ChosenTeamScope team = scene.simulation().StepTeam();
        full_sed->Evaluate(scene.simulation().positions_m(), sed);
        point_fields.push_back({"sed_Pa", 1, std::vector<double>(sed.data(), sed.data() + sed.size())});
      }
      VtuField merkel{"merkel_sed_Pa", 1, std::vector<double>(size_t(scene.model().num_soft_nodes()), 0.0)};
      for (size_t v = 0; v < scene.merkel()->nodes().size(); ++v)
        merkel.values[size_t(scene.merkel()->nodes()[v])] = scene.merkel()->sed_Pa()[Eigen::Index(v)];
      point_fields.push_back(std::move(merkel));
      WriteVtu(options.vtu_dir + "/" + name, scene.model().soft, scene.simulation().positions_m(), point_fields, {},
               {{"step", k}, {"plate_displacement_mm", rec.displacement_mm}, {"force_N", rec.force_N},
                {quasi_static ? "load_parameter" : "time_s", rec.t_s}});
      pvd->Add(quasi_static ? rec.displacement_mm : rec.t_s, name);
    }
    if (options.on_step) options.on_step(rec);
  }
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < result.steps.size(); ++i) {
    const double d = std::abs(result.steps[i].force_N - options.target_force_N);
    if (d < best) {
      best = d;
      result.selected = int(i);
    }
  }
  // Every force non-finite (e.g. contact.stiffness_N_m: 1e300): no step can be selected.
  if (result.selected < 0)
    throw std::runtime_error("press: no step has a finite contact force (" + std::to_string(result.steps.size()) +
                             " steps; check contact.stiffness_N_m and the trajectory), nothing to select for " +
                             std::to_string(options.target_force_N) + " N");
  const Eigen::VectorXd& sed = result.merkel_sed[size_t(result.selected)];
  result.selected_max_sed_Pa = sed.size() ? sed.maxCoeff() : 0.0;
  result.path = scene.merkel()->SamplePath(sed, options.path_y_mm, -options.path_half_width_mm,
                                           options.path_half_width_mm, options.path_step_mm);
  return result;
}

void WritePressCsv(const FingertipScene& scene, const PressResult& result, const std::string& dir) {
  std::filesystem::create_directories(dir);
  auto open = [&](const std::string& name) {
    std::ofstream out(dir + "/" + name);
    if (!out) throw std::runtime_error("cannot write " + dir + "/" + name);
    out << std::setprecision(8);
    return out;
  };
  {
    auto out = open("force_displacement.csv");
    out << "step,displacement_mm,force_N,contact_area_mm2\n";
    for (const auto& s : result.steps)
      out << s.step << "," << s.displacement_mm << "," << s.force_N << "," << s.contact_area_mm2 << "\n";
  }
  const MerkelLayer& merkel = *scene.merkel();
  const Eigen::VectorXd& sed = result.merkel_sed.at(size_t(result.selected));
  {
    // Vertex = Gmsh node tag, so that other solvers' results on the same mesh line up.
    auto out = open("merkel_sed.csv");
    out << "vertex,x_mm,y_mm,z_mm,sed_Pa\n";
    const auto& tags = scene.model().soft_node_tags;
    for (size_t v = 0; v < merkel.nodes().size(); ++v) {
      const int node = merkel.nodes()[v];
      const Eigen::Vector3d p = merkel.rest_pad_mm().col(Eigen::Index(v));
      out << (tags.empty() ? size_t(node) : tags[size_t(node)]) << "," << p.x() << "," << p.y() << "," << p.z() << ","
          << sed[Eigen::Index(v)] << "\n";
    }
  }
  {
    // Not part of the figure contract: what each step cost, for the accuracy-cost study.
    auto out = open("step_timing.csv");
    // threads: the OpenMP team of the step (the step's own choice when OMP_NUM_THREADS is
    // unset: fem/thread_team.h), so a slow press can be told from a slow team choice.
    out << "step,wall_ms,newton_iterations,linear_iterations,solver_fallbacks,converged,inverted_elements,threads\n";
    for (const auto& s : result.steps)
      out << s.step << "," << s.wall_ms << "," << s.report.newton_iterations << "," << s.report.linear_iterations << ","
          << s.report.solver_fallbacks << "," << (s.report.converged ? 1 : 0) << "," << s.report.inverted_elements
          << "," << s.report.threads << "\n";
  }
  {
    // Which step merkel_sed.csv and sed_path.csv show, so plots can say so (and name the model).
    auto out = open("merkel_sed_step.csv");
    const PressStepRecord& sel = result.steps.at(size_t(result.selected));
    out << "model,step,displacement_mm,force_N,max_sed_Pa\n"
        << scene.model().name << "," << sel.step << "," << sel.displacement_mm << "," << sel.force_N << ","
        << result.selected_max_sed_Pa << "\n";
  }
  {
    auto out = open("sed_path.csv");
    out << "x_mm,sed_Pa,sed_normalized\n";
    const double max_sed = result.selected_max_sed_Pa;
    for (const auto& s : result.path) out << s.x_mm << "," << s.sed_Pa << "," << (max_sed > 0 ? s.sed_Pa / max_sed : 0.0) << "\n";
  }
}

}  // namespace sedbridge::scene
