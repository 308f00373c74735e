// The contact QP's dense Cholesky (fem/dense_cholesky.h) against Eigen's LLT, factor +
// solve of an m x m SPD matrix, one thread:
//   build/tests/bench/dense_cholesky_benchmark
// m spans the compliance method's active sets (a few nodes to ~300).

#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "fem/dense_cholesky.h"

namespace sedbridge {
namespace {

Eigen::MatrixXd Spd(int m) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Random(m, m);
  return a * a.transpose() + double(m) * Eigen::MatrixXd::Identity(m, m);
}

void EigenLlt(benchmark::State& state) {
  const int m = int(state.range(0));
  const Eigen::MatrixXd A = Spd(m);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(m);
  Eigen::VectorXd x;
  for (auto _ : state) {
    const auto llt = A.selfadjointView<Eigen::Lower>().llt();
    x = llt.solve(b);
    benchmark::DoNotOptimize(x.data());
  }
}

void DenseCholesky(benchmark::State& state) {
  const int m = int(state.range(0));
  const Eigen::MatrixXd A = Spd(m);
  Eigen::MatrixXd L(m, m);
  Eigen::VectorXd x(m);
  for (auto _ : state) {
    L = A;  // the QP builds its matrix afresh each time, as here
    if (!fem::CholeskyFactorLower(m, L.data(), m)) state.SkipWithError("not SPD");
    x.setOnes();
    fem::CholeskySolveLower(m, L.data(), m, x.data());
    benchmark::DoNotOptimize(x.data());
  }
}

BENCHMARK(EigenLlt)->Arg(20)->Arg(50)->Arg(100)->Arg(150)->Arg(200)->Arg(300)->Unit(benchmark::kMicrosecond);
BENCHMARK(DenseCholesky)->Arg(20)->Arg(50)->Arg(100)->Arg(150)->Arg(200)->Arg(300)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace sedbridge

BENCHMARK_MAIN();
