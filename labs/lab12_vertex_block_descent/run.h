#pragma once
// Lab 12 — given code: what the driver's runs share (main.cpp keeps the flags,
// the run of steps, --convergence and --stability) and its live mode: VBD's
// steps beside a page in the browser (common/live.h; docs/DESIGN.md §3, "The live mode").
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/live.h"
#include "common/scene.h"
#include "descent.h"

namespace cl::lab12 {

struct LabOptions {
  Settings settings;
  std::string init = "adaptive";
  bool estimate = true;  // no --rho: measure it on the scene
  int estimate_iterations = 400;
  int threads = 1;
  bool convergence = false, stability = false;
  std::vector<std::string> sweep_scenes;
};

// --rho, or ρ of plain VBD measured on the scene's first step; 0 for plain VBD.
double rho_for(const Solver& solver, const Scene& scene, Method method, const LabOptions& lab);

// Steps --scene by --method until the page or a signal stops it. Knobs: K
// (sweeps), dt, k (every spring's stiffness, N/m) and, for vbd-chebyshev, rho
// (--rho or the estimate to start). A change of one, a pin or a held particle
// builds the solver again (its colouring and the adaptive guess's history).
int run_live_scene(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, LabOptions lab,
                   const LiveOptions& live);

}  // namespace cl::lab12
