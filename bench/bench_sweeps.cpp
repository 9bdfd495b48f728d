// Throughput of one Gauss-Seidel sweep (lab 02) and one Jacobi sweep (lab 03)
// on cloth of 32² and 128² particles, in distance projections per second.
//
//   build/bin/bench_sweeps --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// Counters: "projections/s" counts what the sweep actually does — Gauss-Seidel
// projects each spring once, the Jacobi gather projects each spring twice (once
// from each end); "springs/s" counts springs satisfied per second, the number
// to compare between the two methods. Wall time throughout (UseRealTime), so
// that the Jacobi runs on 2 threads are not flattered by per-thread CPU time.
#include <omp.h>

#include <numeric>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "common/scene.h"
#include "gauss_seidel.h"
#include "jacobi.h"

namespace {

// A hanging cloth with structural and shear springs, slightly perturbed so
// that no projection is a no-op.
cl::Scene cloth(int n) {
  return cl::parse_scene(R"({"cloth": {"nx": )" + std::to_string(n) + R"(, "ny": )" + std::to_string(n) +
                             R"(, "pin": ["top-left", "top-right"], "springs": ["structural", "shear"],
                             "triangles": false}, "jitter": {"amplitude": 0.002, "seed": 1}})",
                         "bench-cloth.json");
}

void BM_GaussSeidelSweep(benchmark::State& state) {
  const cl::Scene scene = cloth(static_cast<int>(state.range(0)));
  std::vector<int> order(scene.springs.size());
  std::iota(order.begin(), order.end(), 0);
  Eigen::Matrix3Xd x = scene.particles.x;
  for (auto _ : state) {
    cl::lab02::gauss_seidel_sweep(x, scene.particles.inv_mass, scene.springs, order);
    benchmark::DoNotOptimize(x.data());
    benchmark::ClobberMemory();
  }
  const auto springs = static_cast<double>(scene.springs.size());
  state.counters["springs"] = springs;
  state.counters["projections/s"] = benchmark::Counter(springs, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["springs/s"] = benchmark::Counter(springs, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_JacobiSweep(benchmark::State& state) {
  const cl::Scene scene = cloth(static_cast<int>(state.range(0)));
  const int threads = static_cast<int>(state.range(1));
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  const cl::lab03::Incidence incidence = cl::lab03::build_incidence(scene.particles.size(), scene.springs);
  Eigen::Matrix3Xd x = scene.particles.x;
  Eigen::Matrix3Xd x_next = x;
  for (auto _ : state) {
    cl::lab03::jacobi_sweep(x, x_next, scene.particles.inv_mass, scene.springs, incidence, 1.0,
                            cl::lab03::Averaging::kByCount);
    x.swap(x_next);
    benchmark::DoNotOptimize(x.data());
    benchmark::ClobberMemory();
  }
  omp_set_num_threads(saved);
  const auto springs = static_cast<double>(scene.springs.size());
  state.counters["springs"] = springs;
  state.counters["threads"] = threads;
  state.counters["projections/s"] =
      benchmark::Counter(2.0 * springs, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["springs/s"] = benchmark::Counter(springs, benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace

BENCHMARK(BM_GaussSeidelSweep)->ArgName("n")->Arg(32)->Arg(128)->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_JacobiSweep)
    ->ArgNames({"n", "threads"})
    ->Args({32, 1})
    ->Args({32, 2})
    ->Args({128, 1})
    ->Args({128, 2})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
