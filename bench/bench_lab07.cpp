// Lab 07: one constrained step (linearise, assemble, factor, solve, update)
// by the primal-dual KKT solve and by the Schur complement, on the 20-link
// hard chain (ragdoll-chain-20) and on the 64² stiff cloth (stiff-cloth-64).
//
//   build/bin/bench_lab07 --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// Each iteration steps a fresh copy of the scene's initial state, so every
// step solves the same system. Wall time; the ratio KKT/Schur of the medians is
// the number the lab's handout quotes.
//
// The factorizations behind the two, side by side, on the first step's system
// of the 64² stiff cloth and of lab 06's 128² curtain (every c_e > 0):
//   BM_KktFactor/S/F    the (3u + m)-square KKT matrix: F = 0 SparseLU (COLAMD) of
//                       the matrix as written; F = 1 the LDLᵀ of the sign-flipped,
//                       symmetric quasi-definite S with the multipliers first, as
//                       lab 07's solve_kkt does (R = M + (ΔtJ)ᵀC⁻¹(ΔtJ) formed and
//                       factored by SpdFactorization's automatic choice); F = 2
//                       Eigen's SimplicialLDLT of S in its AMD order
//   BM_SchurFactor/S/B  the m × m Schur complement Δt²JWJᵀ + C by SpdFactorization
//                       backend B = 0 simplicial LDLᵀ, 1 CHOLMOD's supernodal LLᵀ
// Each with its analysis (a new pattern every step), as the solves do.
#include <string>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <benchmark/benchmark.h>

#include "common/scene.h"
#include "constrained.h"
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

// The first step's linearised system of a compliant scene.
struct Linearized {
  std::string name;
  cl::lab07::LinearizedStep step;
  cl::lab07::KktSystem kkt;
  cl::SparseMatrix quasi_definite;  // the KKT matrix with its constraint rows negated
  cl::SparseMatrix schur;
};

const char* const kFactorScenes[] = {"labs/lab07_constrained_dynamics/scenes/stiff-cloth-64.json",
                                     "labs/lab06_projective_dynamics/scenes/pd-curtain-128.json"};

const Linearized& linearized(long index) {
  static Linearized cache[2];
  Linearized& made = cache[index];
  if (!made.name.empty()) return made;
  const cl::Scene scene = cl::load_scene(std::string(CL_SOURCE_DIR) + "/" + kFactorScenes[index]);
  made.name = scene.name;
  cl::lab07::StepSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
  made.step = cl::lab07::linearize(scene.particles, scene.springs, map, settings);
  made.kkt = cl::lab07::kkt_system(made.step);
  const Eigen::Index n3 = made.step.velocity.size();
  made.quasi_definite = made.kkt.matrix;
  for (int c = 0; c < made.quasi_definite.outerSize(); ++c) {
    for (cl::SparseMatrix::InnerIterator it(made.quasi_definite, c); it; ++it) {
      if (it.row() >= n3) it.valueRef() = -it.value();
    }
  }
  const cl::SparseMatrix weighted = made.step.inv_mass.asDiagonal() * cl::SparseMatrix(made.step.jacobian.transpose());
  // C on its own diagonal: a spring between two pinned particles has an empty
  // row of J, so JWJᵀ has no diagonal entry there to add to.
  cl::SparseMatrix compliance(made.step.phi.size(), made.step.phi.size());
  compliance.setIdentity();
  compliance.diagonal() = made.step.compliance;
  made.schur = (settings.dt * settings.dt) * (made.step.jacobian * weighted) + compliance;
  made.schur.makeCompressed();
  return made;
}

void BM_KktFactor(benchmark::State& state) {
  const Linearized& system = linearized(state.range(0));
  const long method = state.range(1);
  const char* const names[] = {" sparse-lu", " quasi-definite-ldlt (multipliers first)", " simplicial-ldlt of S (AMD)"};
  state.SetLabel(system.name + names[method]);
  const Eigen::Index n = system.step.velocity.size();
  const Eigen::Index m = system.step.phi.size();
  for (auto _ : state) {
    if (method == 1) {
      const cl::SparseMatrix lower_left = system.kkt.matrix.bottomLeftCorner(m, n);
      const Eigen::VectorXd inverse_compliance = system.kkt.matrix.diagonal().tail(m).cwiseInverse();
      const cl::SparseMatrix reduced = cl::SparseMatrix(system.kkt.matrix.topLeftCorner(n, n)) +
                                       cl::SparseMatrix(lower_left.transpose()) *
                                           (inverse_compliance.asDiagonal() * lower_left);
      cl::SpdFactorization factor;
      if (!factor.factor(reduced)) state.SkipWithError("R is not positive definite");
      state.counters["backend_supernodal"] = factor.backend() == cl::SpdBackend::kSupernodal ? 1.0 : 0.0;
    } else if (method == 2) {
      Eigen::SimplicialLDLT<cl::SparseMatrix> factor(system.quasi_definite);
      if (factor.info() != Eigen::Success) state.SkipWithError("LDLT failed");
      benchmark::DoNotOptimize(factor.vectorD().data());
    } else {
      Eigen::SparseLU<cl::SparseMatrix, Eigen::COLAMDOrdering<int>> factor;
      factor.analyzePattern(system.kkt.matrix);
      factor.factorize(system.kkt.matrix);
      if (factor.info() != Eigen::Success) state.SkipWithError("LU failed");
    }
  }
  state.counters["rows"] = static_cast<double>(system.kkt.matrix.rows());
}

void BM_SchurFactor(benchmark::State& state) {
  const Linearized& system = linearized(state.range(0));
  const cl::SpdBackend backend = state.range(1) == 0 ? cl::SpdBackend::kSimplicial : cl::SpdBackend::kSupernodal;
  double flops = 0.0;
  for (auto _ : state) {
    cl::SpdFactorization factor(backend);
    if (!factor.factor(system.schur)) state.SkipWithError("not positive definite");
    if (factor.backend() != backend) state.SkipWithError("this build has no CHOLMOD");
    flops = factor.flops();
  }
  state.SetLabel(system.name + " " + cl::backend_name(backend));
  state.counters["rows"] = static_cast<double>(system.schur.rows());
  state.counters["flops"] = flops;
}

}  // namespace

BENCHMARK(BM_SchurStep)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_KktStep)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_KktFactor)->Args({0, 0})->Args({0, 1})->Args({0, 2})->Args({1, 1})->Args({1, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SchurFactor)->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
