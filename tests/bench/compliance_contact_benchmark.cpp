// Contact by the compliance method (scene/fingertip_compliance.h) on a fingertip model:
// the precompute, one contact step + Merkel SED at haptic rate, and PressToForce.
// Run (Release build), one thread:
//   OMP_NUM_THREADS=1 build/tests/bench/compliance_contact_benchmark
//   SEDBRIDGE_BENCH_MODEL=B_coarse build/tests/bench/compliance_contact_benchmark --benchmark_filter=Step
//   build/tests/bench/compliance_contact_benchmark --benchmark_filter=BridgePress
//   SEDBRIDGE_BENCH_MERKEL_DISPLAY=suction_4x4 build/tests/bench/compliance_contact_benchmark
//     (the Merkel SED only where that display samples it: bridge fe.merkel_region: display)
//   SEDBRIDGE_BENCH_THREADS=4 ...: the steps and presses on a team of 4 (default 1; the
//     SED's product with G splits by rows above a size: compliance_contact.cpp)
//   SEDBRIDGE_BENCH_SED_KEPT_MIB=0 ...: no kept SED columns (ComplianceContactOptions::
//     sed_kept_columns_MiB; default 64)
// Counters: median_ms / p99_ms / max_ms per step (wall clock), cpu_median_ms / cpu_p99_ms
// (this thread's CPU time: on a shared machine the wall-clock tail is mostly preemption),
// steps_per_s (from the wall median), contacts (active nodes, mean), iterations (outer
// Newton iterations, mean), qp_* (per step: factorizations, factor reuses, columns of T
// computed, combined predictions; sed_kept_new / sed_kept_reads: the SED's kept columns
// computed and read; fem::ComplianceQpCounts); precompute: seconds,
// candidates, SED nodes.

#include <benchmark/benchmark.h>
#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <memory>

#include "display/display_profile.h"
#include "display/sed_to_command_mapping.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge {
namespace {

std::string ModelName() {
  const char* env = std::getenv("SEDBRIDGE_BENCH_MODEL");
  return env ? env : "B";
}

const model::FingertipModel& SharedModel() {
  static const model::FingertipModel model = [] {
    model::FingertipModel m = model::LoadFingertipModel(ModelName());
    const char* display = std::getenv("SEDBRIDGE_BENCH_MERKEL_DISPLAY");
    if (display && *display) {
      auto mapping = std::make_shared<const display::SedToCommandMapping>(display::LoadNamedDisplayProfile(display));
      model::KeepMerkelVertices(
          &m, {[mapping](const Eigen::Vector3d& p) { return mapping->Reads(p.x(), p.y(), p.z()); }, display});
    }
    return m;
  }();
  return model;
}

std::string CacheDir() {
  return (std::filesystem::temp_directory_path() / "sedbridge_compliance_bench_cache").string();
}

// One instance for the step benchmarks (loaded from the cache after the first).
scene::FingertipCompliance& Shared() {
  static scene::FingertipCompliance cc = [] {
    scene::FingertipComplianceOptions o;
    o.contact.cache_dir = CacheDir();
    if (const char* kept = std::getenv("SEDBRIDGE_BENCH_SED_KEPT_MIB")) o.contact.sed_kept_columns_MiB = std::atof(kept);
    return scene::FingertipCompliance(SharedModel(), o);
  }();
  return cc;
}

// This thread's CPU time [ms]: on a shared machine the wall-clock tail is mostly time
// the thread spent preempted; the CPU-time tail is the method's own.
double ThreadCpuMs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

struct Timer {
  std::vector<double> wall_ms, cpu_ms;
  std::chrono::steady_clock::time_point t0;
  double c0 = 0;
  void Start() {
    c0 = ThreadCpuMs();
    t0 = std::chrono::steady_clock::now();
  }
  void Stop() {
    wall_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    cpu_ms.push_back(ThreadCpuMs() - c0);
  }
};

double Percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(q * double(v.size())))];
}

void Report(benchmark::State& state, const Timer& t) {
  const double median = Percentile(t.wall_ms, 0.5);
  state.counters["median_ms"] = median;
  state.counters["p99_ms"] = Percentile(t.wall_ms, 0.99);
  state.counters["max_ms"] = Percentile(t.wall_ms, 1.0);
  state.counters["cpu_median_ms"] = Percentile(t.cpu_ms, 0.5);
  state.counters["cpu_p99_ms"] = Percentile(t.cpu_ms, 0.99);
  state.counters["steps_per_s"] = 1000.0 / median;
}

// Per step: QP matrices factorized anew, factors reused unchanged, rows appended to or
// removed from a factor, columns of W dir
// computed, Anderson moves predicted without a pass over W.
void ReportQpCounts(benchmark::State& state, const fem::ComplianceQpCounts& after, const fem::ComplianceQpCounts& before,
                    double steps) {
  state.counters["qp_factorizations"] = double(after.factorizations - before.factorizations) / steps;
  state.counters["qp_reuses"] = double(after.factor_reuses - before.factor_reuses) / steps;
  state.counters["qp_row_updates"] = double(after.factor_updates - before.factor_updates) / steps;
  state.counters["qp_columns"] = double(after.columns_computed - before.columns_computed) / steps;
  state.counters["qp_combined"] = double(after.combined_predictions - before.combined_predictions) / steps;
  state.counters["sed_kept_new"] = double(after.sed_columns_kept - before.sed_columns_kept) / steps;
  state.counters["sed_kept_reads"] = double(after.sed_kept_reads - before.sed_kept_reads) / steps;
}

// OpenMP team of the steps and presses: SEDBRIDGE_BENCH_THREADS, default 1.
int StepThreads() {
  const char* env = std::getenv("SEDBRIDGE_BENCH_THREADS");
  const int n = env ? std::atoi(env) : 1;
  return n > 0 ? n : 1;
}

geometry::RigidObject Sphere(double radius_mm, double depth_mm) {
  return {"sphere", std::make_shared<geometry::SphereSdf>(radius_mm * 1e-3),
          geometry::Trajectory(Eigen::Isometry3d(Eigen::Translation3d(0, 1e-3, (radius_mm - depth_mm) * 1e-3)))};
}

// Precompute from scratch (no cache): factorize K, one back-substitution per candidate
// dof (state.range(0) threads), W and G.
void Precompute(benchmark::State& state) {
  omp_set_num_threads(int(state.range(0)));
  scene::FingertipComplianceOptions o;
  o.contact.precompute_threads = int(state.range(0));
  double seconds = 0;
  for (auto _ : state) {
    scene::FingertipCompliance cc(SharedModel(), o);
    seconds = cc.contact().precompute_s();
    state.counters["candidates"] = double(cc.contact().candidate_nodes().size());
    state.counters["sed_nodes"] = double(cc.contact().sed_nodes().size());
  }
  state.counters["precompute_s"] = seconds;
}

void CacheLoad(benchmark::State& state) {
  omp_set_num_threads(1);
  Shared();  // writes the cache if missing
  scene::FingertipComplianceOptions o;
  o.contact.cache_dir = CacheDir();
  double seconds = 0;
  bool loaded = false;
  for (auto _ : state) {
    scene::FingertipCompliance cc(SharedModel(), o);
    seconds = cc.contact().precompute_s();
    loaded = cc.contact().loaded_from_cache();
  }
  state.counters["startup_s"] = seconds;
  state.counters["from_cache"] = loaded;
}

// A sphere held on the pad with its depth changing a little every step (a live scan at
// 1 kHz): contact solve warm-started from the last step, then the Merkel SED. The solve's
// relative tolerance is 10^-tol_exp (8: the library's default; 6: the 1e-6 that
// ComplianceContact's full-FE test asks; the bridge's leader press runs at 1e-5).
void SphereStep(benchmark::State& state) {
  omp_set_num_threads(StepThreads());
  const double radius_mm = double(state.range(0)), depth_mm = double(state.range(1)) / 100.0;
  scene::FingertipCompliance& cc = Shared();
  const double default_tolerance = cc.contact().options().relative_tolerance;
  cc.contact().set_relative_tolerance(std::pow(10.0, -double(state.range(2))));
  cc.contact().ResetWarmStart();
  std::vector<geometry::RigidObject> objects{Sphere(radius_mm, depth_mm)};
  const fem::ComplianceQpCounts before = cc.contact().qp_counts();
  Timer timer;
  double contacts = 0, iterations = 0;
  int k = 0;
  for (auto _ : state) {
    objects[0] = Sphere(radius_mm, depth_mm * (1.0 + 0.05 * std::sin(0.05 * k++)));
    timer.Start();
    const fem::ComplianceStepResult& r = cc.Step(objects);
    timer.Stop();
    if (!r.ok || !r.converged) state.SkipWithError("contact step failed");
    contacts += double(r.contacts.size());
    iterations += r.iterations;
  }
  state.counters["contacts"] = contacts / double(timer.wall_ms.size());
  state.counters["iterations"] = iterations / double(timer.wall_ms.size());
  state.counters["force_N"] = cc.normal_force_N();
  cc.contact().set_relative_tolerance(default_tolerance);
  ReportQpCounts(state, cc.contact().qp_counts(), before, double(timer.wall_ms.size()));
  Report(state, timer);
}

// The pad pressed flat by a plane (the paper's press), depth changing a little each step:
// the largest patches (up to the whole candidate set).
void PlaneStep(benchmark::State& state) {
  omp_set_num_threads(StepThreads());
  const double depth_mm = double(state.range(0)) / 100.0;
  scene::FingertipCompliance& cc = Shared();
  cc.contact().ResetWarmStart();
  auto plane = [](double d_mm) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::Vector3d(1, -1, -1).asDiagonal();  // solid above z_pad = -d
    pose.translation() = Eigen::Vector3d(0, 0, -d_mm * 1e-3);
    return geometry::RigidObject{"plane", std::make_shared<geometry::PlaneSdf>(), geometry::Trajectory(pose)};
  };
  std::vector<geometry::RigidObject> objects{plane(depth_mm)};
  const fem::ComplianceQpCounts before = cc.contact().qp_counts();
  Timer timer;
  double contacts = 0, iterations = 0;
  int k = 0;
  for (auto _ : state) {
    objects[0] = plane(depth_mm * (1.0 + 0.05 * std::sin(0.05 * k++)));
    timer.Start();
    const fem::ComplianceStepResult& r = cc.Step(objects);
    timer.Stop();
    if (!r.ok || !r.converged) state.SkipWithError("contact step failed");
    contacts += double(r.contacts.size());
    iterations += r.iterations;
  }
  state.counters["contacts"] = contacts / double(timer.wall_ms.size());
  state.counters["iterations"] = iterations / double(timer.wall_ms.size());
  state.counters["force_N"] = cc.normal_force_N();
  ReportQpCounts(state, cc.contact().qp_counts(), before, double(timer.wall_ms.size()));
  Report(state, timer);
}

// Contact reconstruction's call: a sphere pressed to a force that changes each call, by
// one force-controlled solve (arg 0 = 1) or the root find over indentation-controlled
// solves (0); warm (arg 1 = 0: scan after scan) or from no contact each call (1: a first
// touch).
void PressToForce(benchmark::State& state) {
  omp_set_num_threads(StepThreads());
  scene::FingertipCompliance& cc = Shared();
  cc.contact().ResetWarmStart();
  const std::vector<geometry::RigidObject> sphere{Sphere(8, 0)};
  scene::PressToForceOptions options;
  options.force_control = state.range(0) != 0;
  const bool cold = state.range(1) != 0;
  Timer timer;
  double solves = 0, contacts = 0, outer = 0;
  int k = 0;
  for (auto _ : state) {
    const double target = 1.0 + 0.1 * std::sin(0.05 * k++);
    if (cold) cc.ResetWarmStart();
    timer.Start();
    const scene::PressToForceResult r = cc.PressToForce(sphere, target, options);
    timer.Stop();
    if (!r.reached) state.SkipWithError(r.message.c_str());
    solves += r.iterations;
    contacts += r.active_nodes;
    outer += cc.contact().last().iterations;
  }
  state.counters["contact_solves"] = solves / double(timer.wall_ms.size());
  state.counters["contacts"] = contacts / double(timer.wall_ms.size());
  // Outer iterations of the last solve (force control: of the press's only solve).
  state.counters["last_solve_iterations"] = outer / double(timer.wall_ms.size());
  Report(state, timer);
}

// The bridge's press: face contact (the bridge's default, fe.face_contact), one
// force-controlled solve per call on a ramp, a sphere (arg 0 = 0, R 8 mm) or a rod across the
// pad (1, R 2.5 mm, axis along the pad's x): the reconstructed contact's path in
// `sedbridge replay`, a rod's line of contacts the dearer.
void BridgePress(benchmark::State& state) {
  omp_set_num_threads(StepThreads());
  static scene::FingertipCompliance cc = [] {
    scene::FingertipComplianceOptions o;
    o.contact.cache_dir = CacheDir();
    o.face_samples = true;
    return scene::FingertipCompliance(SharedModel(), o);
  }();
  cc.ResetWarmStart();
  scene::PressToForceOptions options;  // as contact::ReconstructedPressOptions
  options.relative_tolerance = 1e-3;
  options.contact_relative_tolerance = std::pow(10.0, -double(state.range(1)));
  const bool rod = state.range(0) != 0;
  const std::vector<geometry::RigidObject> objects{
      rod ? geometry::RigidObject{"rod", std::make_shared<geometry::CylinderSdf>(2.5e-3, 0.0),
                                  geometry::Trajectory(Eigen::Isometry3d(Eigen::Translation3d(0, 1e-3, 2.5e-3)))}
          : Sphere(8, 0)};
  Timer timer;
  double contacts = 0, outer = 0;
  int k = 0;
  for (auto _ : state) {
    const double target = 0.6 + 0.3 * std::sin(0.05 * k++);
    timer.Start();
    const scene::PressToForceResult r = cc.PressToForce(objects, target, options);
    timer.Stop();
    if (!r.reached) state.SkipWithError(r.message.c_str());
    contacts += r.active_nodes;
    outer += cc.contact().last().iterations;
  }
  state.counters["contacts"] = contacts / double(timer.wall_ms.size());
  state.counters["last_solve_iterations"] = outer / double(timer.wall_ms.size());
  Report(state, timer);
}

void Register() {
  benchmark::RegisterBenchmark("Precompute", Precompute)->Arg(1)->Arg(2)->Iterations(1)->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  benchmark::RegisterBenchmark("CacheLoad", CacheLoad)->Iterations(3)->Unit(benchmark::kMillisecond)->UseRealTime();
  // (radius mm, depth in 1/100 mm, tol_exp): patches from a few nodes to ~200.
  benchmark::RegisterBenchmark("SphereStep", SphereStep)
      ->Args({5, 50, 8})->Args({8, 100, 8})->Args({10, 200, 8})->Args({20, 250, 8})->Args({40, 300, 8})
      ->Args({10, 200, 6})->Args({40, 300, 6})
      ->Iterations(2000)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RegisterBenchmark("PlaneStep", PlaneStep)->Arg(50)->Arg(100)->Arg(200)->Arg(300)->Arg(500)->Arg(700)
      ->Iterations(2000)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RegisterBenchmark("PressToForce", PressToForce)
      ->ArgNames({"force_control", "cold"})->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1})
      ->Iterations(500)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RegisterBenchmark("BridgePress", BridgePress)->ArgNames({"rod", "tol_exp"})
      ->ArgsProduct({{0, 1}, {8, 6, 5, 4, 3}})
      ->Iterations(500)->Unit(benchmark::kMillisecond)->UseRealTime();
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
