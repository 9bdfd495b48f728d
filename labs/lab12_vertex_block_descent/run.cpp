#include "run.h"

#include <cstdio>
#include <optional>

#include "../lab06_projective_dynamics/simulation.h"
#include "common/driver.h"
#include "common/metrics.h"

namespace cl::lab12 {

double rho_for(const Solver& solver, const Scene& scene, Method method, const LabOptions& lab) {
  if (method != Method::kVbdChebyshev) return 0.0;
  if (!lab.estimate) return lab.settings.rho;
  Settings settings = lab.settings;
  settings.gravity = scene.gravity;
  const double rho = solver.estimate_rho(scene.particles, settings, lab.estimate_iterations);
  if (rho < 1.0) return rho;
  std::printf("  estimated rho %.6f >= 1 (plain VBD does not converge here): no acceleration (rho 0)\n", rho);
  return 0.0;
}

int run_live_scene(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, LabOptions lab,
                   const LiveOptions& live) {
  refuse_run_flags(options, "not with --live (the page shows every step)", "");
  const Method method = method_from_name(options.method);
  Scene scene = load_scene_for(options, scene_dir);
  require_finite_springs(scene, "VBD minimises finite springs' energy");
  start_run(options);  // --check stops here, before the colouring runs your code
  Settings& settings = lab.settings;
  settings.gravity = scene.gravity;
  std::optional<Solver> solver;
  solver.emplace(scene.particles.inv_mass, scene.springs, scene.dt);
  settings.rho = rho_for(*solver, scene, method, lab);
  const double k = scene.springs.empty() ? 1.0 : scene.springs.front().stiffness;
  std::vector<Knob> declared{{"K", "sweeps", 0, 100, 1.0 * options.iterations, true},
                             {"dt", "s", 1e-4, 0.05, scene.dt}, {"k", "N/m", 1, 1e10, k}};
  if (method == Method::kVbdChebyshev) declared.push_back({"rho", "", 0, 0.9999, settings.rho});
  LiveRun run{lab_name, options.method, Knobs(declared)};
  BuiltFor built;  // the solver (colours, adjacency) depends on the masses (pins, held particles), dt and k
  run.changed = [&](const Knobs& knobs) -> std::string {
    if (!built.update(scene.particles.inv_mass, {knobs[1], knobs[2]})) return "";
    for (Spring& spring : scene.springs) spring.stiffness = knobs[2];
    solver.emplace(scene.particles.inv_mass, scene.springs, knobs[1]);
    return "the solver (its colouring)";
  };
  run.step = [&](const Knobs& knobs) {
    settings.iterations = knobs.integer(0);
    if (method == Method::kVbdChebyshev) settings.rho = knobs[3];
    const StepReport report = solver->step(scene.particles, method, settings);
    return StepVerdict{report.problem, report.problem.empty()};  // the loop's clock: a rebuilt solver included
  };
  run.energy_name = "total energy";  // kinetic + potential + the springs' elastic
  run.energy = [&](const Particles& state) {
    return kinetic_energy(state) + potential_energy(state, scene.gravity) + lab06::spring_energy(state.x, scene.springs);
  };
  return run_live(scene, live, run, options.summary);
}

}  // namespace cl::lab12
