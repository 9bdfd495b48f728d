#pragma once
// Lab 04 — given code: the driver's options and its experiment, the sweeps of
// iterations or substeps (main.cpp keeps the flags, the dispatch and one run's report).
#include <string>
#include <utility>
#include <vector>

#include "common/cli.h"
#include "pbd.h"

namespace cl::lab04 {

// What lab04_pbd's own flags set (main.cpp).
struct LabOptions {
  int substeps = 1;
  double omega = 1.0;
  double window_seconds = 1.0;     // the averaging window
  double settle_tolerance = 0.02;  // sweeps: stop once three windows agree to this
  double energy_seconds = 2.0;     // sweeps: the energy is compared at this time
  std::vector<int> sweep_iterations;
  std::vector<int> sweep_substeps;
  int cost = 0;                    // substeps × iterations for --sweep-substeps
  std::vector<std::string> sweep_scenes;
};

// The step of one frame of `scene` with `iterations` sweeps of --method's
// projection (and --omega for Jacobi).
PbdSettings frame_settings(const Scene& scene, const CommonOptions& options, const LabOptions& lab, int iterations);

// Runs every scene of --sweep-scenes (default --scene, loaded from scene_dir)
// at every (substeps, iterations) point until it settles (or for --steps
// frames at most) and writes one CSV row per run into OUT/csv_name; prints the
// table, its first line naming `lab_name`. The runs are shared among the
// OpenMP threads, costliest first; each run's wall time is its own.
int run_sweep(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, const LabOptions& lab,
              const std::vector<std::pair<int, int>>& points, const std::string& csv_name);

}  // namespace cl::lab04
