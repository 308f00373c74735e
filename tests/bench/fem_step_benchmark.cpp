// FE step cost on a fingertip model: median and p99 ms/step, steps/s, per-effect
// breakdown. Run (Release build):
//   build/tests/bench/fem_step_benchmark                      # model B, all cases
//   SEDBRIDGE_BENCH_MODEL=B_coarse build/tests/bench/fem_step_benchmark --benchmark_filter=Traction
// Counters: median_ms / p99_ms per step, steps_per_s (from the median), threads; for the
// traction step and the contact press also assembly_ms / solve_ms / sed_ms (mean per step)
// and linear_iterations (PCG iterations per step). ContactPressStep/.../pcg_warp/rest_only
// turns the warped PCG's contact update off (solver.contact_update: false); .../capN accepts
// the PCG iterate after N iterations; force_N is the contact force after the timed steps.
// The argument is the OpenMP team: 1, 2, 4, 8, 16 (as many as the machine has cores), or 0 = chosen by the step itself
// (fem/thread_team.h; `threads` then reports the team it kept at the end, 0 = still measuring).

#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <map>
#include <memory>

#include "fem/cholmod_solver.h"
#include "fem/elastic_tet_force.h"
#include "fem/thread_team.h"
#include "scene/fingertip_scene.h"

namespace sedbridge {
namespace {

std::string ModelName() {
  const char* env = std::getenv("SEDBRIDGE_BENCH_MODEL");
  return env ? env : "B";
}

const model::FingertipModel& SharedModel() {
  static const model::FingertipModel model = model::LoadFingertipModel(ModelName());
  return model;
}

// Team size from the benchmark argument; 0 = the step chooses (all cores to choose from).
void SetThreads(benchmark::State& state) {
  const int threads = int(state.range(0));
  fem::SetAutoThreadTeam(threads == 0);
  omp_set_num_threads(threads == 0 ? omp_get_num_procs() : threads);
  fem::SetBlasThreads(threads == 0 ? 1 : threads);  // CHOLMOD's BLAS too
}

void Report(benchmark::State& state, std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  const double median = ms[ms.size() / 2];
  const double p99 = ms[std::min(ms.size() - 1, size_t(0.99 * double(ms.size())))];
  state.counters["median_ms"] = median;
  state.counters["p99_ms"] = p99;
  state.counters["steps_per_s"] = 1000.0 / median;
  state.counters["threads"] = omp_get_max_threads();
}

// Where the step's time went (mean per step): assembly, solve, SED; PCG iterations per step.
void ReportStages(benchmark::State& state, double linear_iterations, const StageTimes& stage_sum_ms, size_t steps) {
  state.counters["linear_iterations"] = linear_iterations / double(steps);
  for (Stage stage : {Stage::kAssembly, Stage::kSolve, Stage::kSed})
    state.counters[std::string(ToString(stage)) + "_ms"] = stage_sum_ms[stage] / double(steps);
}

void ReportTeam(benchmark::State& state, const fem::Simulation& sim) {
  if (state.range(0) == 0) state.counters["threads"] = sim.thread_team().chosen();
}

// A pressure patch on the pad, as the bridge applies from a taxel grid (1 kPa over ~8x8 mm).
void ApplyPadPressure(scene::FingertipScene& s, double pressure_Pa) {
  auto* traction = s.traction();
  Eigen::Matrix3Xd t = Eigen::Matrix3Xd::Zero(3, Eigen::Index(traction->nodes().size()));
  const Eigen::Vector3d z_pad = s.model().pad_frame.model_from_pad.linear().col(2);
  for (Eigen::Index k = 0; k < t.cols(); ++k) {
    const Eigen::Vector3d p = s.model().pad_frame.ToPad(traction->node_rest_positions_m().col(k)) * 1e3;
    if (p.z() > -1.5 && std::abs(p.x()) < 4 && std::abs(p.y()) < 4) t.col(k) = -pressure_Pa * z_pad;
  }
  traction->SetNodalTraction(t);
}

std::string TractionScene(const std::string& elasticity, const std::string& solver, const std::string& integrator) {
  return "model: " + ModelName() + "\nelasticity: " + elasticity + "\nsolver: {type: " + solver +
         ", tolerance: 1.0e-6, max_iterations: 200}\ndynamics: {integrator: " + integrator +
         ", dt_s: 0.001, newton_iterations: 1}\nbone: {mode: fixed}\nsurface_traction: true\n";
}

// The bridge's step: a pressure patch that varies a little every step (a live scan),
// backward Euler or quasi-static, then the Merkel SED.
void TractionStep(benchmark::State& state, const std::string& elasticity, const std::string& solver,
                  const std::string& integrator) {
  SetThreads(state);
  scene::FingertipScene s(scene::ParseSceneDescription(TractionScene(elasticity, solver, integrator), "bench"),
                          SharedModel());
  std::vector<double> ms;
  int k = 0;
  for (int warm = 0; warm < 3; ++warm) s.Step();
  double linear_iterations = 0;
  StageTimes stage_sum_ms;
  for (auto _ : state) {
    ApplyPadPressure(s, 1000.0 + 200.0 * std::sin(0.05 * k++));
    const auto t0 = std::chrono::steady_clock::now();
    const fem::StepReport r = s.Step();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    linear_iterations += r.linear_iterations;
    stage_sum_ms.Add(r.stage_ms);
  }
  ReportStages(state, linear_iterations, stage_sum_ms, ms.size());
  Report(state, ms);
  ReportTeam(state, s.simulation());
}

// The paper's press, dynamic: backward Euler at 1 ms with penalty contact, the plane
// pushed 2 mm in 1 s; timed while in contact.
// A solver name ending in "/rest_only" turns the contact update of the warped PCG off
// (solver.contact_update: false): the rest factor alone, as before that update; one
// ending in "/double" keeps the warped rest factor's solves in double precision
// (solver.single_precision_factor: false), as before they went to single precision; "/capN" accepts the PCG
// iterate after N iterations (max_iterations: N, no direct fallback: the accuracy-cost
// study's capped rows; matrix-free, fem/step_operator.h), "/capN/assembled" the same with
// the element blocks assembled (solver.matrix_free: false). `force_N` is the contact force after the timed steps, so rows can be
// compared for what they compute, not only for how fast.
void ContactPressStep(benchmark::State& state, const std::string& elasticity, const std::string& solver_case) {
  SetThreads(state);
  auto ends_with = [&](const std::string& suffix) {
    return solver_case.size() > suffix.size() &&
           solver_case.compare(solver_case.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  const bool rest_only = ends_with("/rest_only"), double_factor = ends_with("/double");
  const bool assembled = ends_with("/assembled");
  const size_t cap_at = solver_case.find("/cap");
  const std::string iterations =
      cap_at == std::string::npos
          ? "max_iterations: 200"
          : "max_iterations: " + std::to_string(std::atoi(solver_case.c_str() + cap_at + 4)) +
                ", fallback_to_direct: false" + (assembled ? ", matrix_free: false" : "");
  const std::string solver = solver_case.substr(0, solver_case.find('/'));
  const std::string yaml = "model: " + ModelName() + "\nelasticity: " + elasticity + "\nsolver: {type: " + solver +
                           ", tolerance: 1.0e-6, " + iterations + (rest_only ? ", contact_update: false" : "") +
                           (double_factor ? ", single_precision_factor: false" : "") +
                           "}\n"
                           "dynamics: {integrator: backward_euler, dt_s: 0.001, newton_iterations: 1}\n"
                           "bone: {mode: fixed}\ncontact:\n  objects:\n    - {shape: plane, rpy_deg: [180, 0, 0], "
                           "position_mm: [0, 0, -0.5], motion: {keyframes: [{t_s: 0, offset_mm: [0, 0, 0]}, "
                           "{t_s: 1.0, offset_mm: [0, 0, -1.5]}]}}\n";
  scene::FingertipScene s(scene::ParseSceneDescription(yaml, "bench"), SharedModel());
  std::vector<double> ms;
  for (int warm = 0; warm < 3; ++warm) s.Step();
  double linear_iterations = 0;
  StageTimes stage_sum_ms;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const fem::StepReport r = s.Step();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    linear_iterations += r.linear_iterations;
    stage_sum_ms.Add(r.stage_ms);
  }
  state.counters["contacts"] = double(s.contact()->active_contacts().size());
  state.counters["force_N"] = s.contact()->TotalSpringForceMagnitude();
  ReportStages(state, linear_iterations, stage_sum_ms, ms.size());
  Report(state, ms);
  ReportTeam(state, s.simulation());
}

// Per-effect breakdown: force + Jacobian of each term alone, and the pieces of a solve.
void EffectCost(benchmark::State& state, const std::string& effect) {
  SetThreads(state);
  // The nodal pressure term exists only in a scene that asks for it.
  std::string yaml = "model: " + ModelName() + (effect == "nodal_pressure" ? "\nelasticity: nodal_pressure" : "") +
                     "\nbone: {}\nsurface_traction: true\n"
                     "contact:\n  objects: [{shape: plane, rpy_deg: [180, 0, 0], position_mm: [0, 0, -1.0]}]\n"
                     "friction: {anisotropy: 0.3}\noutputs: {merkel_sed: true}\n";
  scene::FingertipScene s(scene::ParseSceneDescription(yaml, "bench"), SharedModel());
  ApplyPadPressure(s, 1000.0);
  s.Step();
  auto& sim = s.simulation();
  fem::SystemMatrix A;
  std::vector<std::pair<int, int>> pairs;
  for (const auto& t : sim.terms()) t->AppendCoupledNodes(pairs);
  A.Build(s.model().num_soft_nodes(), pairs);
  for (const auto& t : sim.terms()) t->BindMatrix(A);
  fem::JacobianSink sink{&A, 1e-6, 1e-3};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(sim.positions_m().size());
  const fem::SystemState st{sim.positions_m(), sim.velocities_m_s(), sim.time_s(), true};
  fem::ForceTerm* term = nullptr;
  for (const auto& t : sim.terms())
    if (t->name() == effect) term = t.get();
  std::vector<double> ms;
  Eigen::VectorXd sed;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    if (effect == "merkel_sed") {
      s.merkel()->Evaluate(sim.positions_m());
    } else {
      f.setZero();
      term->AddForce(st, f, &sink);
    }
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  Report(state, ms);
}

// One product with the step matrix of the corotational term on B: from the assembled matrix
// (arg 0: CSR product over the whole matrix) or from the element kernel (arg 1: the
// matrix-free step's, fem/step_operator.h). Single thread.
void StepProduct(benchmark::State& state) {
  omp_set_num_threads(1);
  const model::FingertipModel& m = SharedModel();
  fem::ElasticTetForce elastic(m.soft, fem::ElasticFormulation::kCorotational, 0.01);
  std::vector<std::pair<int, int>> pairs;
  elastic.AppendCoupledNodes(pairs);
  fem::SystemMatrix A;
  A.Build(m.soft.num_nodes(), pairs);
  elastic.BindMatrix(A);
  const Eigen::Matrix3Xd& rest = m.soft.rest_positions_m;
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(rest.data(), rest.size());
  x += 1e-5 * Eigen::VectorXd::Random(x.size());
  const Eigen::VectorXd v = Eigen::VectorXd::Random(x.size());
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size()), y = Eigen::VectorXd::Zero(x.size());
  fem::JacobianSink sink{&A, 1e-6, 1e-3};
  elastic.AddForce({x, v, 0.0, true}, f, &sink);
  const bool from_elements = state.range(0) != 0;
  std::vector<double> ms;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    if (from_elements) {
      y.setZero();
      elastic.AddJacobianTimes(1e-6, 1e-3, v, y);
    } else {
      A.Multiply(v, y);
    }
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    benchmark::DoNotOptimize(y.data());
  }
  Report(state, ms);
}

// Thread columns: 1, 2, 4, 8, 16 where the machine has that many cores (more would only
// measure oversubscription), then 0 = the step's own choice (ThreadTeamChooser).
template <typename B>
B* ThreadArgs(B* b, bool with_auto = true) {
  const int cores = omp_get_num_procs();
  for (int t : {1, 2, 4, 8, 16})
    if (t <= 2 || t <= cores) b->Arg(t);
  if (with_auto) b->Arg(0);
  return b;
}

void Register() {
  for (const char* integrator : {"backward_euler", "quasi_static"})
    for (auto [el, solver] : std::vector<std::pair<const char*, const char*>>{
             {"linear", "ldlt"}, {"linear", "cholmod"}, {"corotational", "pcg_warp"},
             {"corotational", "pcg_warp_ldlt"}, {"corotational", "pcg_warp_ichol"}, {"corotational", "pcg_jacobi"},
             {"corotational", "ldlt"}, {"corotational", "cholmod"}, {"nodal_pressure", "pcg_warp"},
             {"nodal_pressure", "pcg_jacobi"}, {"nodal_pressure", "ldlt"}}) {
      if (std::string(integrator) == "quasi_static" && std::string(el) != "linear") continue;
      const std::string name = std::string("TractionStep/") + integrator + "/" + el + "/" + solver;
      ThreadArgs(benchmark::RegisterBenchmark(name.c_str(),
                                              [=](benchmark::State& st) { TractionStep(st, el, solver, integrator); }))
          ->Iterations((std::string(solver) == "ldlt" || std::string(solver) == "cholmod") &&
                                            std::string(el) != "linear" ? 10 : 200)
          ->Unit(benchmark::kMillisecond)->UseRealTime();
    }
  for (auto [el, solver] : std::vector<std::pair<const char*, const char*>>{
           {"linear", "ldlt"}, {"linear", "cholmod"}, {"corotational", "pcg_warp"}, {"corotational", "pcg_warp/rest_only"},
           {"corotational", "pcg_warp/double"}, {"corotational", "pcg_warp/cap3"}, {"corotational", "pcg_warp/cap1"},
           {"corotational", "pcg_warp/cap1/assembled"},
           {"corotational", "pcg_warp_ldlt"}, {"corotational", "pcg_warp_ichol"}, {"linear", "pcg_warp"},
           {"linear", "pcg_warp/rest_only"}, {"linear", "pcg_warp/double"}, {"linear", "pcg_warp_ldlt"},
           {"linear", "pcg_warp_ichol"}, {"nodal_pressure", "pcg_warp"}, {"nodal_pressure", "pcg_jacobi"}}) {
    const std::string name = std::string("ContactPressStep/backward_euler/") + el + "/" + solver;
    ThreadArgs(benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& st) { ContactPressStep(st, el, solver); }))
        ->Iterations(200)->Unit(benchmark::kMillisecond)->UseRealTime();
  }
  benchmark::RegisterBenchmark("StepProduct", StepProduct)->ArgName("from_elements")->Arg(0)->Arg(1)
      ->Iterations(500)->Unit(benchmark::kMillisecond)->UseRealTime();
  for (const char* effect : {"elastic_corotational", "nodal_pressure", "bone_coupling", "penalty_contact", "pseudo_friction",
                             "surface_traction", "merkel_sed"}) {
    const std::string name = std::string("EffectCost/") + effect;
    ThreadArgs(benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& st) { EffectCost(st, effect); }), false)
        ->Iterations(200)->Unit(benchmark::kMillisecond)->UseRealTime();
  }
}

}  // namespace
}  // namespace sedbridge

int main(int argc, char** argv) {
  sedbridge::Register();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
