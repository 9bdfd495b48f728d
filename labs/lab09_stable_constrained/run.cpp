#include "run.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/driver.h"
#include "stable_step.h"

namespace cl::lab09 {

int run_live_scene(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                   const LabOptions& lab, const LiveOptions& live) {
  refuse_run_flags(options, "not with --live (the page shows every step)", "");
  Scene scene = load_scene_for(options, scene_dir);
  const bool finite = !scene.springs.empty() && std::all_of(scene.springs.begin(), scene.springs.end(),
                                                             [](const Spring& s) { return std::isfinite(s.stiffness); });
  std::vector<Knob> declared{{"dt", "s", 1e-4, 0.05, scene.dt},
                             {"Kg", "off/on", 0, 1, lab.geometric_stiffness == "on" ? 1.0 : 0.0, true}};
  if (finite) declared.push_back({"k", "N/m", 1, 1e10, scene.springs.front().stiffness});
  LiveRun run{lab_name, options.method, Knobs(declared)};

  StableSettings settings = settings_for(scene, options, lab, lab.geometric_stiffness == "on");
  MovableMap map;
  Eigen::VectorXd lambda;  // the previous step's multipliers: K_g's λ̄
  BuiltFor built;  // the unknowns' map and the multipliers depend on the masses (pins, held particles) and k
  run.changed = [&](const Knobs& knobs) -> std::string {
    if (!built.update(scene.particles.inv_mass, {finite ? knobs[2] : 0.0})) return "";
    map = make_movable_map(scene.particles.inv_mass);  // a pin or a held particle is no longer an unknown
    if (finite) {
      for (Spring& spring : scene.springs) spring.stiffness = knobs[2];
    }
    lambda.resize(0);
    return "the unknowns' map and the multipliers";
  };
  run.step = [&](const Knobs& knobs) -> StepVerdict {
    settings.step.dt = knobs[0];
    settings.geometric_stiffness = knobs.integer(1) == 1;
    const StableStepResult result = stable_step(scene.particles, scene.springs, map, settings, lambda);
    if (!result.ok) return {"failed: " + result.problem, false};
    lambda = result.lambda;
    return {};
  };
  run.energy_name = "total energy";  // kinetic + potential + the finite springs' elastic
  run.energy = [&](const Particles& state) { return total_energy(state, scene); };
  return run_live(scene, live, run, options.summary);
}

}  // namespace cl::lab09
