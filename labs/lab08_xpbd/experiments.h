#pragma once
// Lab 08 — given code: the driver's options and its experiment, the sweep of
// the iteration count (main.cpp keeps the flags, the dispatch and one run's report).
#include <string>
#include <vector>

#include "common/cli.h"
#include "simulation.h"

namespace cl::lab08 {

// What lab08_xpbd's own flags set (main.cpp).
struct LabOptions {
  int substeps = 1;
  double window_seconds = 1.0;      // the averaging window
  double settle_tolerance = 1e-3;   // sweeps: stop once three windows agree to this
  std::vector<int> sweep_iterations;
};

// The step of one frame of `scene`: --method, `iterations` sweeps, --substeps.
FrameSettings frame_settings(const Scene& scene, const CommonOptions& options, const LabOptions& lab, int iterations);

// Runs --scene (loaded from scene_dir) once per K of --sweep-iterations until
// its total stretch is steady (or for --steps frames at most) and writes one
// row per K into OUT/stretch_vs_iterations_<method>.csv; prints the table, its
// first line naming `lab_name`. The runs are shared among the OpenMP threads,
// costliest first; each row's seconds is its own.
int run_sweep(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, const LabOptions& lab);

}  // namespace cl::lab08
