#pragma once
// Lab 10 — given code: the driver's options, what its run and its experiment
// share, and the experiment (--converge); main.cpp keeps the flags, the
// dispatch and one run's report.
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/hierarchy.h"
#include "common/scene.h"

namespace cl::lab10 {

// What lab10_hierarchical_pbd's own flags set (main.cpp).
struct LabOptions {
  int levels = 3;
  std::vector<int> iterations_per_level{8};
  bool converge = false;
  std::vector<std::string> sweep_scenes;
  std::vector<int> sweep_levels;
  std::vector<double> targets{0.05, 0.01};
  int max_sweeps = 20000;
  double max_projections = 0.0;  // 0: no limit beyond max_sweeps
};

// The summary's method: one level is plain Gauss-Seidel PBD.
const char* method_name(int levels);

// The counts joined by `separator` ("4,4,4").
std::string join(const std::vector<int>& values, const char* separator = ",");

// The hierarchy of `levels` levels on the scene's cloth. Throws InputError for
// a scene without a cloth grid or more levels than its grid has, naming `flag`
// (the option that gave the level count: --levels, or --sweep-levels).
ClothHierarchy hierarchy_for(const Scene& scene, int levels, const std::string& flag = "--levels");

// --iterations-per-level: one count for every level, or one per level (the
// cloth first). Throws InputError for any other number of counts.
std::vector<int> per_level(const LabOptions& lab, int levels);

// Experiment 1: one step from rest of every scene of --sweep-scenes (default
// --scene, loaded from scene_dir) for every level count of --sweep-levels
// (default --levels); the projections until the cloth's max strain reaches
// each --targets value -> OUT/convergence.csv, OUT/to_target.csv, the table on
// the terminal (its first line naming `lab_name`), and for one scene and one
// level count the --summary. Throws InputError for bad input before any work.
int run_converge(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                 const LabOptions& lab);

}  // namespace cl::lab10
