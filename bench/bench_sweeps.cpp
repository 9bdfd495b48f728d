// What one sweep costs, per spring: Gauss-Seidel (lab 02), Jacobi (lab 03)
// and XPBD (lab 08) on cloths of 32² and 128² particles.
//
//   build/bin/bench_sweeps --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// Each sweep is timed twice, in the same run: the reference's sweep, which
// checks its arrays once and projects with the formula inline, and the sweep
// as the stubs describe it ("calling"), which calls the checked projection of
// lab 01 (or lab 08) once per spring — a call the compiler cannot inline
// (another library) and the projection's argument checks every time. The
// calling sweeps here are the references' sweeps as they were before issue 52,
// and give the same bits. A third Gauss-Seidel sweep visits the springs in
// colour order (greedy edge colouring: no two springs of a colour share a
// particle), the same work without the wait for the previous projection.
//
// After the benchmarks, a summary prints ns per spring (median CPU time of a
// sweep over the number of springs), the ratios between sweeps at each size and
// each sweep's 128² over its 32² per spring, which the handouts of labs 02,
// 04 and 08 quote (labs/labNN/claims.json reads them). CPU time, not wall
// time: on a shared machine the wall clock counts the other jobs' turns. The
// Jacobi sweeps run on one thread here (the 2-thread rows: wall time).
// XPBD is timed as whole steps of K = 20 sweeps (the reference's sweep is
// inside xpbd_step), so its figure carries 1/20 of a step's own work
// (prediction, α̃ per spring, the checks).
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "common/openmp.h"
#include "common/scene.h"
#include "gauss_seidel.h"
#include "jacobi.h"
#include "single_spring.h"
#ifdef CL_BENCH_XPBD
#include "pbd.h"
#include "xpbd.h"
#endif

namespace {

constexpr int kXpbdSweeps = 20;

// A hanging cloth with structural and shear springs, slightly perturbed so
// that no projection is a no-op.
cl::Scene cloth(int n) {
  return cl::parse_scene(R"({"cloth": {"nx": )" + std::to_string(n) + R"(, "ny": )" + std::to_string(n) +
                             R"(, "pin": ["top-left", "top-right"], "springs": ["structural", "shear"],
                             "triangles": false}, "jitter": {"amplitude": 0.002, "seed": 1}})",
                         "bench-cloth.json");
}

std::vector<int> file_order(const cl::Scene& scene) {
  std::vector<int> order(scene.springs.size());
  std::iota(order.begin(), order.end(), 0);
  return order;
}

// Greedy edge colouring, then the springs colour by colour: no two springs in
// a row share a particle (except where one colour ends and the next begins).
std::vector<int> colour_order(const cl::Scene& scene) {
  const auto n = static_cast<std::size_t>(scene.particles.size());
  std::vector<unsigned> used(n, 0);  // bit c: a spring of colour c touches the particle
  std::vector<std::vector<int>> colours;
  for (std::size_t s = 0; s < scene.springs.size(); ++s) {
    const auto i = static_cast<std::size_t>(scene.springs[s].i), j = static_cast<std::size_t>(scene.springs[s].j);
    unsigned c = 0;
    while ((used[i] | used[j]) & (1u << c)) ++c;
    used[i] |= 1u << c;
    used[j] |= 1u << c;
    if (colours.size() <= c) colours.resize(c + 1);
    colours[c].push_back(static_cast<int>(s));
  }
  std::vector<int> order;
  for (const auto& colour : colours) order.insert(order.end(), colour.begin(), colour.end());
  return order;
}

// The Gauss-Seidel sweep as the stub describes it: lab 01's project_distance,
// checks and all, once per spring.
void gauss_seidel_calling(Eigen::Matrix3Xd& x, const Eigen::VectorXd& inv_mass, const std::vector<cl::Spring>& springs,
                          const std::vector<int>& order) {
  for (const int s : order) {
    const cl::Spring& spring = springs[static_cast<std::size_t>(s)];
    const cl::lab01::DistanceCorrection correction = cl::lab01::project_distance(
        x.col(spring.i), x.col(spring.j), inv_mass[spring.i], inv_mass[spring.j], spring.rest_length);
    x.col(spring.i) += correction.dx_i;
    x.col(spring.j) += correction.dx_j;
  }
}

// The Jacobi gather the same way (one thread).
void jacobi_calling(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& x_next, const Eigen::VectorXd& inv_mass,
                    const std::vector<cl::Spring>& springs, const cl::lab03::Incidence& incidence) {
  for (Eigen::Index p = 0; p < x.cols(); ++p) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const auto begin = static_cast<std::size_t>(incidence.offset[static_cast<std::size_t>(p)]);
    const auto end = static_cast<std::size_t>(incidence.offset[static_cast<std::size_t>(p) + 1]);
    for (std::size_t k = begin; k < end; ++k) {
      const cl::Spring& spring = springs[static_cast<std::size_t>(incidence.spring[k])];
      const cl::lab01::DistanceCorrection correction = cl::lab01::project_distance(
          x.col(spring.i), x.col(spring.j), inv_mass[spring.i], inv_mass[spring.j], spring.rest_length);
      sum += spring.i == p ? correction.dx_i : correction.dx_j;
    }
    const double count = end > begin ? static_cast<double>(end - begin) : 1.0;
    x_next.col(p) = x.col(p) + (1.0 / count) * sum;
  }
}

void count_springs(benchmark::State& state, double springs, double projections_per_spring) {
  state.counters["springs"] = springs;
  state.counters["projections/s"] =
      benchmark::Counter(projections_per_spring * springs, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["springs/s"] = benchmark::Counter(springs, benchmark::Counter::kIsIterationInvariantRate);
}

template <bool kCalling>
void gauss_seidel(benchmark::State& state, bool colour) {
  const cl::Scene scene = cloth(static_cast<int>(state.range(0)));
  const std::vector<int> order = colour ? colour_order(scene) : file_order(scene);
  Eigen::Matrix3Xd x = scene.particles.x;
  for (auto _ : state) {
    if constexpr (kCalling) {
      gauss_seidel_calling(x, scene.particles.inv_mass, scene.springs, order);
    } else {
      cl::lab02::gauss_seidel_sweep(x, scene.particles.inv_mass, scene.springs, order);
    }
    benchmark::DoNotOptimize(x.data());
    benchmark::ClobberMemory();
  }
  count_springs(state, static_cast<double>(scene.springs.size()), 1.0);
}
void BM_GaussSeidelSweep(benchmark::State& state) { gauss_seidel<false>(state, false); }
void BM_GaussSeidelSweepCalling(benchmark::State& state) { gauss_seidel<true>(state, false); }
void BM_GaussSeidelSweepColoured(benchmark::State& state) { gauss_seidel<false>(state, true); }

template <bool kCalling>
void jacobi(benchmark::State& state) {
  const cl::Scene scene = cloth(static_cast<int>(state.range(0)));
  const int threads = kCalling ? 1 : static_cast<int>(state.range(1));
  const int saved = cl::openmp_max_threads();
  cl::set_openmp_threads(threads);
  const cl::lab03::Incidence incidence = cl::lab03::build_incidence(scene.particles.size(), scene.springs);
  Eigen::Matrix3Xd x = scene.particles.x;
  Eigen::Matrix3Xd x_next = x;
  for (auto _ : state) {
    if constexpr (kCalling) {
      jacobi_calling(x, x_next, scene.particles.inv_mass, scene.springs, incidence);
    } else {
      cl::lab03::jacobi_sweep(x, x_next, scene.particles.inv_mass, scene.springs, incidence, 1.0,
                              cl::lab03::Averaging::kByCount);
    }
    x.swap(x_next);
    benchmark::DoNotOptimize(x.data());
    benchmark::ClobberMemory();
  }
  cl::set_openmp_threads(saved);
  state.counters["threads"] = threads;
  count_springs(state, static_cast<double>(scene.springs.size()), 2.0);
}
void BM_JacobiSweep(benchmark::State& state) { jacobi<false>(state); }
void BM_JacobiSweepCalling(benchmark::State& state) { jacobi<true>(state); }

#ifdef CL_BENCH_XPBD
// The XPBD step as the stub describes it: project_distance_xpbd, checks and
// all, once per spring in each of the K sweeps (the step's own checks left out).
void xpbd_step_calling(cl::Particles& particles, const cl::lab04::ConstraintSet& constraints,
                       const cl::lab08::XpbdSettings& settings, Eigen::VectorXd& lambda) {
  const double dt = settings.dt;
  const std::vector<cl::Spring>& springs = constraints.springs;
  std::vector<double> alpha_tilde(springs.size());
  for (std::size_t s = 0; s < springs.size(); ++s) alpha_tilde[s] = cl::lab08::compliance(springs[s]) / (dt * dt);
  Eigen::Matrix3Xd predicted = particles.x;
  for (Eigen::Index p = 0; p < particles.size(); ++p) {
    if (particles.inv_mass[p] > 0.0) predicted.col(p) += dt * (particles.v.col(p) + dt * settings.gravity);
  }
  lambda.setZero(static_cast<Eigen::Index>(springs.size()));
  for (int k = 0; k < settings.iterations; ++k) {
    for (const int s : constraints.order) {
      const cl::Spring& spring = springs[static_cast<std::size_t>(s)];
      const cl::lab08::XpbdCorrection correction = cl::lab08::project_distance_xpbd(
          predicted.col(spring.i), predicted.col(spring.j), particles.inv_mass[spring.i],
          particles.inv_mass[spring.j], spring.rest_length, alpha_tilde[static_cast<std::size_t>(s)], lambda[s]);
      predicted.col(spring.i) += correction.dx_i;
      predicted.col(spring.j) += correction.dx_j;
      lambda[s] += correction.dlambda;
    }
  }
  particles.v = (predicted - particles.x) / dt;
  particles.x = predicted;
}

template <bool kCalling>
void xpbd(benchmark::State& state) {
  const cl::Scene scene = cloth(static_cast<int>(state.range(0)));
  const cl::lab04::ConstraintSet constraints = cl::lab04::make_constraint_set(scene.particles.size(), scene.springs);
  cl::lab08::XpbdSettings settings;
  settings.iterations = kXpbdSweeps;
  cl::Particles particles = scene.particles;
  Eigen::VectorXd lambda;
  for (auto _ : state) {
    // Each timed step starts from the scene, so that every run sees the same states.
    state.PauseTiming();
    particles = scene.particles;
    state.ResumeTiming();
    if constexpr (kCalling) {
      xpbd_step_calling(particles, constraints, settings, lambda);
    } else {
      cl::lab08::xpbd_step(particles, constraints, settings, lambda);
    }
    benchmark::DoNotOptimize(particles.x.data());
    benchmark::ClobberMemory();
  }
  count_springs(state, kXpbdSweeps * static_cast<double>(scene.springs.size()), 1.0);
}
void BM_XpbdStep(benchmark::State& state) { xpbd<false>(state); }
void BM_XpbdStepCalling(benchmark::State& state) { xpbd<true>(state); }
#endif

// Whether a run ended in an error or was skipped: Google Benchmark 1.7
// (Debian 12) says so in `error_occurred`, 1.8 and later (Debian 13, Homebrew)
// in `skipped`, which replaced it.
template <typename Run>
auto run_failed(const Run& run, int) -> decltype(static_cast<bool>(run.error_occurred)) {
  return run.error_occurred;
}
template <typename Run>
bool run_failed(const Run& run, long) {
  return static_cast<bool>(run.skipped);
}

// Remembers each run's CPU time per iteration for the summary: the median
// aggregate when the runs were repeated, else the median of the runs. It
// prints as the library's own reporter does: in colour on a terminal only, so
// that a pipe reads plain `BM_` lines (./course test counts them).
class Collector : public benchmark::ConsoleReporter {
 public:
  Collector() : ConsoleReporter(isatty(STDOUT_FILENO) ? OO_Defaults : OO_Tabular) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run_failed(run, 0)) continue;
      const bool median = run.run_type == Run::RT_Aggregate && run.aggregate_name == "median";
      if (run.run_type == Run::RT_Aggregate && !median) continue;
      Entry& entry = entries_[run.run_name.str()];
      const double ns = run.GetAdjustedCPUTime() / benchmark::GetTimeUnitMultiplier(run.time_unit) * 1e9;
      (median ? entry.median : entry.runs).push_back(ns);
      const auto springs = run.counters.find("springs");
      if (springs != run.counters.end()) entry.springs = springs->second.value;
    }
  }
  bool empty() const { return entries_.empty(); }
  // ns per spring of the benchmark `name`, 0 when it did not run.
  double per_spring(const std::string& name) const {
    const auto found = entries_.find(name);
    if (found == entries_.end() || found->second.springs <= 0.0) return 0.0;
    std::vector<double> values = found->second.median.empty() ? found->second.runs : found->second.median;
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    return values[values.size() / 2] / found->second.springs;
  }

 private:
  struct Entry {
    std::vector<double> runs, median;
    double springs = 0.0;
  };
  std::map<std::string, Entry> entries_;
};

void summary(const Collector& runs) {
  if (runs.empty()) return;  // --benchmark_list_tests, or a filter that matched nothing
  std::printf("\nsweep cost, ns per spring (CPU time, median):\n");
  std::printf("  %-7s %9s %9s %9s %9s %9s %9s %9s\n", "cloth", "GS", "GS-call", "GS-colour", "Jacobi", "Jac-call",
              "XPBD", "XPBD-call");
  for (const int n : {32, 128}) {
    const std::string arg = "/n:" + std::to_string(n);
    const double gs = runs.per_spring("BM_GaussSeidelSweep" + arg);
    const double gs_call = runs.per_spring("BM_GaussSeidelSweepCalling" + arg);
    const double gs_colour = runs.per_spring("BM_GaussSeidelSweepColoured" + arg);
    const double jacobi = runs.per_spring("BM_JacobiSweep" + arg + "/threads:1/real_time");
    const double jacobi_call = runs.per_spring("BM_JacobiSweepCalling" + arg);
    const double xpbd = runs.per_spring("BM_XpbdStep" + arg);
    const double xpbd_call = runs.per_spring("BM_XpbdStepCalling" + arg);
    if (gs + gs_call + gs_colour + jacobi + jacobi_call + xpbd + xpbd_call == 0.0) continue;  // none ran
    std::printf("  %3d²    %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f   (0: not run)\n", n, gs, gs_call, gs_colour,
                jacobi, jacobi_call, xpbd, xpbd_call);
    auto ratio = [&](const char* what, double a, double b) {
      if (a > 0.0 && b > 0.0) std::printf("ratio %s at %d²: %.2f\n", what, n, a / b);
    };
    ratio("gauss-seidel calling / reference", gs_call, gs);
    ratio("jacobi calling / reference", jacobi_call, jacobi);
    ratio("xpbd calling / reference", xpbd_call, xpbd);
    ratio("gauss-seidel file order / colour order", gs, gs_colour);
    ratio("jacobi / gauss-seidel", jacobi, gs);
    ratio("xpbd / gauss-seidel", xpbd, gs);
  }
  // Per spring, the large cloth against the small one: 1 when the sweep's
  // time does not grow with the data it moves (the 128² cloth's positions,
  // masses and springs, about 2.3 MB, overflow a core's cache below the shared
  // one; the 32² cloth's, about 0.14 MB, do not).
  auto size_ratio = [&](const char* what, const std::string& name, const std::string& tail) {
    const double small = runs.per_spring(name + "/n:32" + tail), large = runs.per_spring(name + "/n:128" + tail);
    if (small > 0.0 && large > 0.0) std::printf("ratio %s 128² / 32²: %.2f\n", what, large / small);
  };
  size_ratio("gauss-seidel", "BM_GaussSeidelSweep", "");
  size_ratio("gauss-seidel colour order", "BM_GaussSeidelSweepColoured", "");
  size_ratio("jacobi", "BM_JacobiSweep", "/threads:1/real_time");
  size_ratio("xpbd", "BM_XpbdStep", "");
}

}  // namespace

BENCHMARK(BM_GaussSeidelSweep)->ArgName("n")->Arg(32)->Arg(128)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_GaussSeidelSweepCalling)->ArgName("n")->Arg(32)->Arg(128)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_GaussSeidelSweepColoured)->ArgName("n")->Arg(32)->Arg(128)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_JacobiSweep)
    ->ArgNames({"n", "threads"})
    ->Args({32, 1})
    ->Args({32, 2})
    ->Args({128, 1})
    ->Args({128, 2})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_JacobiSweepCalling)->ArgName("n")->Arg(32)->Arg(128)->Unit(benchmark::kMicrosecond);
#ifdef CL_BENCH_XPBD
BENCHMARK(BM_XpbdStep)->ArgName("n")->Arg(32)->Arg(128)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_XpbdStepCalling)->ArgName("n")->Arg(32)->Arg(128)->Unit(benchmark::kMicrosecond);
#endif

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  Collector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  benchmark::Shutdown();
  summary(collector);
  return 0;
}
