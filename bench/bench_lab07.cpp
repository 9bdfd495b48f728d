// Lab 07: one constrained step (linearise, assemble, factor, solve, update)
// by the primal-dual KKT solve and by the Schur complement, on the 20-link
// hard chain (ragdoll-chain-20) and on the 64² stiff cloth (stiff-cloth-64).
//
//   build/bin/bench_lab07 --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// Each iteration steps a fresh copy of the scene's initial state, so every
// step solves the same system. Wall time; the ratio KKT/Schur of the medians is
// the number the lab's handout quotes.
#include <string>

#include <benchmark/benchmark.h>

#include "common/scene.h"
#include "step.h"

namespace {

const char* const kScenes[] = {"ragdoll-chain-20", "stiff-cloth-64"};

cl::Scene scene_number(long index) {
  return cl::load_scene(std::string(CL_SOURCE_DIR) + "/labs/lab07_constrained_dynamics/scenes/" +
                        kScenes[index] + ".json");
}

void BM_Step(benchmark::State& state, cl::lab07::Method method) {
  const cl::Scene scene = scene_number(state.range(0));
  state.SetLabel(kScenes[state.range(0)]);
  cl::lab07::StepSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.method = method;
  const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
  for (auto _ : state) {
    state.PauseTiming();
    cl::Particles particles = scene.particles;
    state.ResumeTiming();
    const cl::lab07::StepResult result = cl::lab07::constrained_step(particles, scene.springs, map, settings);
    if (!result.ok) {
      state.SkipWithError(result.problem.c_str());
      break;
    }
    benchmark::DoNotOptimize(particles.x.data());
  }
  state.counters["springs"] = static_cast<double>(scene.springs.size());
  state.counters["unknowns"] = static_cast<double>(3 * map.unknowns());
}

void BM_SchurStep(benchmark::State& state) { BM_Step(state, cl::lab07::Method::kSchur); }
void BM_KktStep(benchmark::State& state) { BM_Step(state, cl::lab07::Method::kKkt); }

}  // namespace

BENCHMARK(BM_SchurStep)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_KktStep)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
