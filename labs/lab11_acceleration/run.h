#pragma once
// Lab 11 — given code: what the driver's runs share (main.cpp keeps the flags,
// the run of steps and --convergence) and its live mode: the accelerated steps
// beside a page in the browser (common/live.h; docs/DESIGN.md §3, "The live mode").
#include <string>
#include <vector>

#include "accelerated.h"
#include "common/cli.h"
#include "common/live.h"
#include "common/scene.h"

namespace cl::lab11 {

struct LabOptions {
  Settings settings;
  bool estimate = true;  // no --rho: measure it on the scene
  bool convergence = false;
  std::vector<std::string> sweep_scenes;
  double strain_target = 1e-3;
  int estimate_iterations = 400;
};

// The scenes of a run (--scene) or of --convergence (--sweep-scenes), each
// refused when the chosen method minimises g and a spring is hard.
std::vector<Scene> load(const CommonOptions& options, const std::vector<std::string>& names, Method method,
                        const std::string& scene_dir);

// --rho, or ρ measured on the scene's first step (Wang: once per scene); 0 without Chebyshev.
double rho_for(Solver& solver, const Scene& scene, Method method, const LabOptions& lab);

// Steps --scene by --method until the page or a signal stops it. Knobs: K
// (iterations or sweeps), dt, and the acceleration's: rho (the Chebyshev
// methods; --rho or the estimate to start) or history (pd-lbfgs's m). A change
// of one, a pin or a held particle builds the solver again (PD's A refactored
// on the step after it).
int run_live_scene(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, LabOptions lab,
                   const LiveOptions& live);

}  // namespace cl::lab11
