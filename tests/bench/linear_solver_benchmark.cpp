// Direct solver cost on a fingertip model's step matrix: non-zeros in L, symbolic
// analysis, numeric factorization and one solve, Eigen's simplicial LDL^T (DirectLdltSolver)
// against CHOLMOD's supernodal L L^T (CholmodSolver) with each ordering. Run (Release):
//   build/tests/bench/linear_solver_benchmark --threads 1 B_coarse B B_fine B_x4 A
// (SEDBRIDGE_BENCH_ONLY_DEFAULT=1: LDL^T and the default CHOLMOD ordering's two solve paths only.)
// Prints one markdown table row per model and solver. --threads sets both the OpenMP and
// the BLAS (OpenBLAS) thread counts, --blas-threads the BLAS alone (after --threads).
// Times are medians over repetitions (wall clock).
//
// The matrix is the backward Euler step matrix at rest, corotational elasticity with the
// bone fixed: M + h D + h^2 K at h = 1 ms (what pcg_warp factorizes once and "ldlt" every
// step with contact or corotational elasticity).

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "fem/cholmod_solver.h"
#include "fem/lumped_mass.h"
#include "scene/fingertip_scene.h"

namespace sedbridge {
namespace {

double Ms(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Repetitions for a step that took `first_ms`: about `budget_ms` in all, 3..max.
int Reps(double first_ms, double budget_ms, int max) {
  return std::clamp(int(budget_ms / std::max(first_ms, 1e-3)), 3, max);
}

void BuildStepMatrix(const model::FingertipModel& model, fem::SystemMatrix& A) {
  const std::string yaml = "model: " + model.name +
                           "\nelasticity: corotational\ndynamics: {integrator: backward_euler, dt_s: 0.001}\n"
                           "bone: {mode: fixed}\n";
  scene::FingertipScene s(scene::ParseSceneDescription(yaml, "bench"), model);
  auto& sim = s.simulation();
  std::vector<std::pair<int, int>> pairs;
  for (const auto& t : sim.terms()) t->AppendCoupledNodes(pairs);
  A.Build(model.num_soft_nodes(), pairs);
  for (const auto& t : sim.terms()) t->BindMatrix(A);
  const double h = 1e-3;
  fem::JacobianSink sink{&A, h * h, h};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(sim.positions_m().size());
  const fem::SystemState st{sim.positions_m(), sim.velocities_m_s(), sim.time_s(), true};
  for (const auto& t : sim.terms()) t->AddForce(st, f, &sink);
  const Eigen::VectorXd m = fem::LumpedNodeMass(model.soft);
  for (int i = 0; i < model.num_soft_nodes(); ++i) A.AddScaledIdentity(A.DiagonalSlot(i), m[i]);
}

// nnz(L) of Eigen's LDL^T with its AMD ordering, diagonal (D) included, as CHOLMOD counts.
double LdltNonZeros(const fem::SystemMatrix& A) {
  const auto& m = A.csr();
  const Eigen::Map<const Eigen::SparseMatrix<double>> a(m.rows(), m.cols(), m.nonZeros(), m.outerIndexPtr(),
                                                        m.innerIndexPtr(), m.valuePtr());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
  ldlt.analyzePattern(a);
  ldlt.factorize(a);
  return double(ldlt.matrixL().nestedExpression().nonZeros()) + double(a.rows());
}

void Measure(const std::string& model_name, const fem::SystemMatrix& A, const std::string& label,
             fem::LinearSolver& solver, double nnz_l, double stored, const std::function<std::string()>& ordering) {
  const Eigen::Index n = A.csr().rows();
  const double first = Ms([&] { solver.Prepare(A); });  // symbolic analysis + first factorization
  std::vector<double> factor;
  const int fr = Reps(first, 3000.0, 20);
  for (int r = 0; r < fr; ++r) factor.push_back(Ms([&] { solver.Prepare(A); }));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd b(n), x(n), ax;
  for (Eigen::Index i = 0; i < n; ++i) b[i] = u(rng);
  std::vector<double> solve;
  const double first_solve = Ms([&] { solver.Solve(A, b, x); });
  const int sr = Reps(first_solve, 1000.0, 200);
  for (int r = 0; r < sr; ++r) solve.push_back(Ms([&] { solver.Solve(A, b, x); }));
  A.Multiply(x, ax);
  const double residual = (ax - b).norm() / b.norm();
  if (nnz_l == 0) {
    auto* c = dynamic_cast<fem::CholmodSolver*>(&solver);
    nnz_l = c->factor_nonzeros();
    stored = c->factor_stored_entries();
  }
  std::printf("| %s | %ld | %d | %s | %s | %.3f | %.3f | %.1f | %.1f (%d) | %.3f (%d) | %.1e |\n", model_name.c_str(),
              long(n), omp_get_max_threads(), label.c_str(), ordering().c_str(), nnz_l * 1e-6, stored * 1e-6, first,
              Median(factor), fr, Median(solve), sr, residual);
  std::fflush(stdout);
}

}  // namespace
}  // namespace sedbridge

int main(int argc, char** argv) {
  using namespace sedbridge;
  std::vector<std::string> models;
  int threads = 0, blas_threads = 0;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--threads") == 0 && i + 1 < argc) threads = std::atoi(argv[++i]);
    else if (std::strcmp(argv[i], "--blas-threads") == 0 && i + 1 < argc) blas_threads = std::atoi(argv[++i]);
    else models.push_back(argv[i]);
  }
  if (models.empty()) models = {"B_coarse", "B"};
  if (threads > 0) {
    omp_set_num_threads(threads);
    fem::SetBlasThreads(threads);
  }
  if (blas_threads > 0) fem::SetBlasThreads(blas_threads);
  { fem::CholmodSolver applies_the_default_blas_threads; }
  std::printf("OpenMP threads %d, BLAS threads %d\n\n", omp_get_max_threads(), fem::BlasThreads());
  std::printf("| model | unknowns | OpenMP threads | solver | ordering | nnz(L) M | stored L M | analyze + 1st factor ms | "
              "factor ms (reps) | solve ms (reps) | rel. residual |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& name : models) {
    const model::FingertipModel model = model::LoadFingertipModel(name);
    fem::SystemMatrix A;
    BuildStepMatrix(model, A);
    const double ldlt_nnz = LdltNonZeros(A);
    {
      fem::DirectLdltSolver ldlt;
      Measure(name, A, "Eigen SimplicialLDLT", ldlt, ldlt_nnz, ldlt_nnz, [] { return std::string("amd"); });
    }
    // The default ordering with each triangular-solve path (kAuto picks the subtrees
    // when there is more than one OpenMP thread).
    for (auto [path, label] : {std::pair{fem::CholmodSolvePath::kCholmod, "CHOLMOD (best of AMD, METIS), CHOLMOD's solve"},
                               std::pair{fem::CholmodSolvePath::kSubtrees, "CHOLMOD (best of AMD, METIS), subtree solve"}}) {
      fem::CholmodSolver cholmod(fem::CholmodOrdering::kBest);
      cholmod.set_solve_path(path);
      Measure(name, A, label, cholmod, 0, 0, [&] { return cholmod.ordering_used(); });
      if (path == fem::CholmodSolvePath::kSubtrees)
        std::printf("|   (subtree solve: %.1f %% of L's entries on the serial top) |||||||||||\n",
                    100.0 * cholmod.solve_serial_fraction());
    }
    if (std::getenv("SEDBRIDGE_BENCH_ONLY_DEFAULT")) continue;
    for (auto [ordering, label] : {std::pair{fem::CholmodOrdering::kAmd, "CHOLMOD supernodal"},
                                   std::pair{fem::CholmodOrdering::kMetis, "CHOLMOD supernodal"}}) {
      fem::CholmodSolver cholmod(ordering);
      Measure(name, A, label, cholmod, 0, 0, [&] { return cholmod.ordering_used(); });
    }
  }
  return 0;
}
