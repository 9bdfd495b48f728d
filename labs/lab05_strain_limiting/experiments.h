#pragma once
// Lab 05 — given code: the driver's options, what its run and its experiments
// share, and the two experiments (--compare-limits, --stability-map); main.cpp
// keeps the flags, the dispatch and one run's report.
#include <string>
#include <vector>

#include "common/cli.h"
#include "simulation.h"

namespace cl::lab05 {

// What lab05_strain_limiting's own flags set (main.cpp).
struct LabOptions {
  std::string limit = "springs";
  double sigma_min = 0.9;
  double sigma_max = 1.1;
  std::vector<std::string> compare_limits;
  bool stability_map = false;
  std::vector<double> map_stiffness{1e1, 1e2, 1e3, 1e4, 1e5, 1e6};
  std::vector<double> map_dt{1e-4, 5e-4, 2e-3, 1e-2, 1.0 / 30.0};
  double map_seconds = 1.0;
};

// The step of `scene` with --iterations, the band and `limit`.
StepSettings step_settings(const Scene& scene, const CommonOptions& options, const LabOptions& lab, Limit limit);

// parse_limit, its error an InputError about --limit.
Limit limit_from(const std::string& name);

// "ok", or "unstable at step N: problem".
std::string status_of(const RunResult& result);

// Wall time per step done, s (0 when none was).
double per_step(const RunResult& result);

// Empty when a spring-limited run kept every spring inside the band, up to
// band_tolerance(K), for the whole run; otherwise one line saying how far out
// it went. Triangle limiters bound triangles, not springs: nothing to check.
std::string band_problem(const RunResult& result, Limit limit, const LabOptions& lab, int iterations);

// Unlimited runs are checked for energy as well: that is how an explicit step
// that blows up is caught before its strain reaches kUnstableStrain. Limited
// runs are not (README.md, "Bounded only by the limiter").
bool checks_energy(Limit limit);

// Experiment 1: --scene (from scene_dir) once per limiter of --compare-limits,
// one after the other -> OUT/strain_vs_time.csv, compare_limits.csv,
// shapes.csv and the table on the terminal (its first line naming `lab_name`).
int compare_limits(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                   const LabOptions& lab);

// Experiment 2: --scene (from scene_dir) at every (--map-stiffness, --map-dt)
// cell, unlimited and, where that blows up, with --limit, the cells shared
// among the OpenMP threads -> OUT/stability_map.csv and the table. Throws
// InputError, after loading the scene, for no limiter, --dt, --steps or --summary.
int stability_map(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                  const LabOptions& lab);

}  // namespace cl::lab05
