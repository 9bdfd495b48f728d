#include "run.h"

#include <cstdio>
#include <optional>
#include <utility>

#include "../lab06_projective_dynamics/simulation.h"
#include "common/driver.h"
#include "common/metrics.h"
#include "common/openmp.h"

namespace cl::lab11 {

std::vector<Scene> load(const CommonOptions& options, const std::vector<std::string>& names, Method method,
                        const std::string& scene_dir) {
  std::vector<Scene> scenes = load_scenes(options, names, scene_dir);
  for (const Scene& scene : scenes) {
    if (!minimises_objective(method)) break;
    require_finite_springs(scene, std::string(method_name(method)) + " needs finite springs (or a PBD method)");
  }
  return scenes;
}

double rho_for(Solver& solver, const Scene& scene, Method method, const LabOptions& lab) {
  if (!lab.estimate || (method != Method::kPdChebyshev && method != Method::kJacobiChebyshev)) return lab.settings.rho;
  Settings settings = lab.settings;
  settings.gravity = scene.gravity;
  const double rho = solver.estimate_rho(scene.particles, method, settings, lab.estimate_iterations);
  if (rho < 1.0) return rho;
  std::printf("  estimated rho %.6f >= 1 (the plain iteration does not converge): no acceleration (rho 0)\n", rho);
  return 0.0;
}

int run_live_scene(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, LabOptions lab,
                   const LiveOptions& live) {
  refuse_run_flags(options, "not with --live (the page shows every step)", "");
  // One thread: the loop sleeps between steps, and on a busy machine each of a
  // Jacobi sweep's parallel regions waited for a descheduled thread (110 ms a
  // step of jacobi-chebyshev on pd-curtain-16 against 0.5 ms on one thread).
  cl::set_openmp_threads(1);
  const Method method = method_from_name(options.method);
  Scene scene = std::move(load(options, {}, method, scene_dir).front());
  start_run(options);  // --check stops here, before the estimate of rho runs your code
  Settings& settings = lab.settings;
  settings.gravity = scene.gravity;
  std::optional<Solver> solver;
  solver.emplace(scene.particles.inv_mass, scene.springs, scene.dt);
  settings.rho = rho_for(*solver, scene, method, lab);
  const bool chebyshev = method == Method::kPdChebyshev || method == Method::kJacobiChebyshev;
  const char* unit = minimises_objective(method) ? "iterations" : "sweeps";
  std::vector<Knob> declared{{"K", unit, 0, 100, 1.0 * options.iterations, true},
                             {"dt", "s", 1e-4, 0.05, scene.dt}};
  if (chebyshev) declared.push_back({"rho", "", 0, 0.9999, settings.rho});
  if (method == Method::kPdLbfgs) declared.push_back({"history", "pairs", 0, 50, 1.0 * settings.history, true});
  LiveRun run{lab_name, options.method, Knobs(declared)};
  BuiltFor built;  // A depends on the masses (pins, held particles) and dt
  run.changed = [&](const Knobs& knobs) -> std::string {
    if (!built.update(scene.particles.inv_mass, {knobs[1]})) return "";
    solver.emplace(scene.particles.inv_mass, scene.springs, knobs[1]);
    return "A, factored again";
  };
  run.step = [&](const Knobs& knobs) {
    settings.iterations = knobs.integer(0);
    if (chebyshev) settings.rho = knobs[2];
    if (method == Method::kPdLbfgs) settings.history = knobs.integer(2);
    const StepReport report = solver->step(scene.particles, method, settings);
    return StepVerdict{report.problem, report.problem.empty()};  // the loop's clock: a refactorization included
  };
  if (minimises_objective(method)) {
    run.energy_name = "total energy";  // kinetic + potential + the springs' elastic
    run.energy = [&](const Particles& state) {
      return kinetic_energy(state) + potential_energy(state, scene.gravity) + lab06::spring_energy(state.x, scene.springs);
    };
  }
  return run_live(scene, live, run, options.summary);
}

}  // namespace cl::lab11
