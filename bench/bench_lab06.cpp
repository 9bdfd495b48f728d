// Lab 06: the cost of one projective dynamics iteration on the curtains, its
// parts, and the factorizations behind it (reference code).
//
//   build/bin/bench_lab06 --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// The pairs to compare, measured side by side in one run:
//   BM_Solve3AgainstEigen/128  both solves below alternately in one loop: medians and their ratio
//   BM_Solve3OnePass/128       vs  BM_EigenSolve3Columns/128   the three-coordinate solve with the
//                                  stored factor: one pass over L (common/sparse) against Eigen's
//                                  solve of an n × 3 right-hand side (one pass per column)
//   BM_PdIteration/128         local step + right-hand side + solve3, the whole iteration
//   BM_Factorization/128       SimplicialLDLT of A (AMD ordering + numeric), once per scene
//   BM_FactorBackends/M/N/B    the numeric factorization alone (refactor: the analysis kept, as
//                              Newton does every iteration) of matrix M (0: PD's A, n × n;
//                              1: Newton's Hessian, 3n × 3n) at size N² by backend B (0: Eigen's
//                              simplicial LDLᵀ, 1: CHOLMOD's supernodal LLᵀ, when built with
//                              it), with the flop count that SpdBackend::kAutomatic compares
//                              with kSupernodalFlops (common/sparse.h)
//   BM_SolveBackends/M/N/B     the three-coordinate solve3 with that factor
//   BM_NewtonHessianAssembly/N the Hessian's values into its fixed pattern, once per iteration
// Wall time throughout (UseRealTime).
#include <algorithm>
#include <map>
#include <vector>
#include <string>

#include <benchmark/benchmark.h>

#include "common/scene.h"
#include "common/sparse.h"
#include "common/timer.h"
#include "projective_dynamics.h"
#include "simulation.h"

namespace {

// The shipped curtain after a few PD steps (so that the springs are not at
// rest and the local step does real work).
struct Curtain {
  cl::Scene scene;
  cl::lab06::Problem problem;
  cl::SparseMatrix a;
  Eigen::Matrix3Xd y;  // the next step's prediction
};

const Curtain& curtain(int n) {
  static std::map<int, Curtain> cache;
  auto found = cache.find(n);
  if (found != cache.end()) return found->second;
  Curtain made;
  made.scene = cl::load_scene(std::string(CL_SOURCE_DIR) + "/labs/lab06_projective_dynamics/scenes/pd-curtain-" +
                              std::to_string(n) + ".json");
  made.problem = cl::lab06::make_problem(made.scene.particles.inv_mass, made.scene.springs, made.scene.dt);
  made.a = cl::lab06::system_matrix(made.problem);
  cl::lab06::Solver solver(made.problem, cl::lab06::Method::kProjectiveDynamics);
  cl::lab06::StepSettings settings;
  settings.gravity = made.scene.gravity;
  for (int s = 0; s < 5; ++s) solver.step(made.scene.particles, settings);
  made.y = cl::lab06::predict(made.scene.particles, made.scene.gravity, made.scene.dt);
  return cache.emplace(n, std::move(made)).first->second;
}

void count_unknowns(benchmark::State& state, const Curtain& c) {
  state.counters["unknowns"] = c.problem.map.unknowns();
  state.counters["springs"] = static_cast<double>(c.problem.springs.size());
}

cl::RowsX3 right_hand_side_of(const Curtain& c) {
  return cl::lab06::right_hand_side(c.problem, c.y, cl::lab06::local_step(c.y, c.problem.springs));
}

void BM_Solve3OnePass(benchmark::State& state) {
  const Curtain& c = curtain(static_cast<int>(state.range(0)));
  cl::SpdFactorization factor(cl::SpdBackend::kSimplicial);
  factor.factor(c.a);
  const cl::RowsX3 b = right_hand_side_of(c);
  for (auto _ : state) {
    cl::RowsX3 x = factor.solve3(b);
    benchmark::DoNotOptimize(x.data());
    benchmark::ClobberMemory();
  }
  count_unknowns(state, c);
  state.counters["nnz(L)"] = static_cast<double>(factor.eigen().matrixL().nestedExpression().nonZeros());
}

void BM_EigenSolve3Columns(benchmark::State& state) {
  const Curtain& c = curtain(static_cast<int>(state.range(0)));
  cl::SpdFactorization factor(cl::SpdBackend::kSimplicial);
  factor.factor(c.a);
  const Eigen::MatrixX3d b = right_hand_side_of(c);  // column-major: Eigen's natural layout
  for (auto _ : state) {
    Eigen::MatrixX3d x = factor.eigen().solve(b);
    benchmark::DoNotOptimize(x.data());
    benchmark::ClobberMemory();
  }
  count_unknowns(state, c);
}

// The two solves alternately in one loop, each timed on its own, so that both
// see the same machine (a shared machine's load changes within seconds).
// Counters: the median of each and their ratio.
void BM_Solve3AgainstEigen(benchmark::State& state) {
  const Curtain& c = curtain(static_cast<int>(state.range(0)));
  cl::SpdFactorization factor(cl::SpdBackend::kSimplicial);
  factor.factor(c.a);
  const cl::RowsX3 b = right_hand_side_of(c);
  const Eigen::MatrixX3d b_columns = b;
  std::vector<double> one_pass, eigen;
  for (auto _ : state) {
    cl::Timer timer;
    cl::RowsX3 x = factor.solve3(b);
    benchmark::DoNotOptimize(x.data());
    one_pass.push_back(timer.seconds());
    timer.restart();
    Eigen::MatrixX3d y = factor.eigen().solve(b_columns);
    benchmark::DoNotOptimize(y.data());
    eigen.push_back(timer.seconds());
    state.SetIterationTime(one_pass.back() + eigen.back());
  }
  auto median = [](std::vector<double> values) {
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
    return values[values.size() / 2];
  };
  if (!one_pass.empty()) {
    state.counters["solve3_us"] = 1e6 * median(one_pass);
    state.counters["eigen_us"] = 1e6 * median(eigen);
    state.counters["eigen/solve3"] = median(eigen) / median(one_pass);
  }
  count_unknowns(state, c);
}

void BM_PdIteration(benchmark::State& state) {
  const Curtain& c = curtain(static_cast<int>(state.range(0)));
  cl::SpdFactorization factor;
  factor.factor(c.a);
  Eigen::Matrix3Xd x = c.y;
  for (auto _ : state) {
    const Eigen::Matrix3Xd d = cl::lab06::local_step(x, c.problem.springs);
    x = cl::lab06::global_step(c.problem, factor, c.y, d);
    benchmark::DoNotOptimize(x.data());
    benchmark::ClobberMemory();
  }
  count_unknowns(state, c);
}

void BM_LocalStep(benchmark::State& state) {
  const Curtain& c = curtain(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    Eigen::Matrix3Xd d = cl::lab06::local_step(c.y, c.problem.springs);
    benchmark::DoNotOptimize(d.data());
  }
  count_unknowns(state, c);
}

void BM_Factorization(benchmark::State& state) {
  const Curtain& c = curtain(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    cl::SpdFactorization factor(cl::SpdBackend::kSimplicial);
    benchmark::DoNotOptimize(factor.factor(c.a));
  }
  count_unknowns(state, c);
}

// The matrix of BM_FactorBackends and BM_SolveBackends: PD's A or Newton's Hessian.
const cl::SparseMatrix& matrix_of(const Curtain& c, long which) {
  static std::map<int, cl::SparseMatrix> hessians;
  if (which == 0) return c.a;
  const int n = static_cast<int>(c.problem.map.unknowns());
  auto found = hessians.find(n);
  if (found == hessians.end()) found = hessians.emplace(n, cl::lab06::newton_hessian(c.problem, c.y)).first;
  return found->second;
}

cl::SpdBackend backend_of(long index) {
  return index == 0 ? cl::SpdBackend::kSimplicial : cl::SpdBackend::kSupernodal;
}

// Labels the run with its matrix and backend, or skips it when the backend is
// not there (CHOLMOD without a build that found it).
bool describe(benchmark::State& state, const cl::SpdFactorization& factor) {
  const std::string matrix = state.range(0) == 0 ? "A" : "hessian";
  if (factor.backend() != backend_of(state.range(2))) {
    state.SkipWithError("this build has no CHOLMOD");
    return false;
  }
  state.SetLabel(matrix + " " + cl::backend_name(factor.backend()));
  state.counters["rows"] = static_cast<double>(factor.size());
  state.counters["flops"] = factor.flops();
  return true;
}

void BM_FactorBackends(benchmark::State& state) {
  const Curtain& c = curtain(static_cast<int>(state.range(1)));
  const cl::SparseMatrix& matrix = matrix_of(c, state.range(0));
  cl::SpdFactorization factor(backend_of(state.range(2)));
  if (!factor.factor(matrix)) {
    state.SkipWithError("not positive definite");
    return;
  }
  if (!describe(state, factor)) return;
  for (auto _ : state) benchmark::DoNotOptimize(factor.refactor(matrix));
}

void BM_SolveBackends(benchmark::State& state) {
  const Curtain& c = curtain(static_cast<int>(state.range(1)));
  const cl::SparseMatrix& matrix = matrix_of(c, state.range(0));
  cl::SpdFactorization factor(backend_of(state.range(2)));
  if (!factor.factor(matrix)) {
    state.SkipWithError("not positive definite");
    return;
  }
  if (!describe(state, factor)) return;
  const cl::RowsX3 b = cl::RowsX3::Ones(matrix.rows(), 3);
  for (auto _ : state) {
    cl::RowsX3 x = factor.solve3(b);
    benchmark::DoNotOptimize(x.data());
  }
}

void BM_NewtonHessianAssembly(benchmark::State& state) {
  const Curtain& c = curtain(static_cast<int>(state.range(0)));
  cl::lab06::HessianAssembly assembly(c.problem);
  for (auto _ : state) {
    const cl::SparseMatrix& hessian = assembly.update(c.problem, c.y);
    benchmark::DoNotOptimize(hessian.valuePtr());
  }
  count_unknowns(state, c);
}

}  // namespace

// The ≥ 2× comparison first: interleaved, then each on its own.
BENCHMARK(BM_Solve3AgainstEigen)->Arg(128)->Arg(32)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Solve3OnePass)->Arg(128)->Arg(32)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_EigenSolve3Columns)->Arg(128)->Arg(32)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PdIteration)->Arg(128)->Arg(64)->Arg(32)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LocalStep)->Arg(128)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Factorization)->Arg(128)->Arg(64)->Arg(32)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NewtonHessianAssembly)->Arg(128)->Arg(64)->UseRealTime()->Unit(benchmark::kMillisecond);
// Matrix × size × backend: each size's two backends one after the other.
BENCHMARK(BM_FactorBackends)
    ->ArgsProduct({{0, 1}, {32, 64, 128}, {0, 1}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SolveBackends)
    ->ArgsProduct({{0, 1}, {64, 128}, {0, 1}})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
