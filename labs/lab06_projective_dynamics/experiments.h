#pragma once
// Lab 06 — given code: the driver's options, what its run and its experiment
// share, and the experiment (--convergence); main.cpp keeps the flags, the
// dispatch and one run's report.
#include <optional>
#include <string>
#include <vector>

#include "common/cli.h"
#include "simulation.h"

namespace cl::lab06 {

// What lab06_projective_dynamics's own flags set (main.cpp).
struct LabOptions {
  double tolerance = 0.0;
  std::optional<double> stiffness;  // replaces every spring's stiffness
  bool convergence = false;
  int warmup = 0;
  int pd_cap = 3000;
  int newton_cap = 50;
  double stop_gap = 1e-9;           // the experiment ends PD at this relative error
  double max_seconds = 0.0;         // the experiment ends a run after this wall time (0: no limit)
  std::vector<std::string> sweep_scenes;
};

// The scene `name` (from scene_dir, --dt and --steps applied) with --stiffness
// applied; hard constraints are refused here with InputError, naming the
// spring and `lab_name` (lab 07 is the lab for them).
Scene load_finite_scene(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                        const LabOptions& lab, const std::string& name);

// The objective's problem of the scene (its springs, masses and dt).
Problem problem_of(const Scene& scene);

// Experiments 1 and 2: one step of every scene of --sweep-scenes (default
// --scene), after --warmup PD steps, to its minimum with Newton and then PD
// -> OUT/convergence.csv (the curves), OUT/crossover.csv (iterations and time
// to 1e-2, 1e-3, 1e-6) and the table on the terminal (its first line naming `lab_name`).
int run_convergence(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                    const LabOptions& lab);

}  // namespace cl::lab06
