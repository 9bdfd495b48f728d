#pragma once
// Lab 13 — given code: the driver's options, the stiffness override, and the
// experiment (--convergence); main.cpp keeps the flags, the dispatch and one
// run's report.
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/scene.h"
#include "iteration.h"

namespace cl::lab13 {

// What lab13_constrained_newton's own flags set (main.cpp).
struct LabOptions {
  Settings settings;            // start, warm, tolerance, compression (iterations: --iterations)
  std::string stiffness;        // --stiffness: empty (the scene's), a number > 0 (N/m) or "inf"
  bool convergence = false;
  std::vector<std::string> sweep_scenes;
  std::vector<std::string> stiffnesses{"1e2", "1e4", "1e6", "1e8"};  // inf: on hard-curtain-32 (README.md)
  std::vector<std::string> starts{"x"};
  std::vector<std::string> warms{"forces"};
  int warmup = 10;              // constrained Newton steps before the measured one
  int newton_cap = 50;          // the most iterations of each method in the experiment
  int pd_cap = 3000;
  double max_seconds = 20.0;    // the experiment ends a run after this wall time
};

// "inf" or a finite number > 0 (N/m); InputError naming `flag` otherwise.
double parse_stiffness(const std::string& flag, const std::string& text);

// Every spring of `scene` with stiffness k (N/m, or inf: hard).
void set_stiffness(Scene& scene, double k);

// Experiments 1 and 2 (README.md): for every scene of --sweep-scenes (default
// --scene) and every k of --stiffnesses, --warmup constrained Newton steps
// from the scene's start, then ONE step from there to its converged result
// x* by constrained Newton (every --starts × --warms), lab 06's Newton and PD
// (finite k only), each to a relative distance 1e-6 of x*:
//     distance = rms_p ‖x_p − x*_p‖ / rms_p ‖x*_p − x_start,p‖.
// -> OUT/convergence.csv (every iteration), OUT/crossover.csv (iterations and
// seconds to 1e-2, 1e-3, 1e-6) and the table on the terminal.
int run_convergence(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                    const LabOptions& lab);

}  // namespace cl::lab13
