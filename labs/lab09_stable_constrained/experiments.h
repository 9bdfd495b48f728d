#pragma once
// Lab 09 — given code: the driver's options, what its run and its experiment
// share, and the experiment (--sweep-mass-ratios); main.cpp keeps the flags,
// the dispatch and one run's report.
#include <string>
#include <vector>

#include "common/cli.h"
#include "stable_step.h"

namespace cl::lab09 {

// What lab09_stable_constrained's own flags set (main.cpp).
struct LabOptions {
  std::string geometric_stiffness = "on";
  std::string compression = "drop";
  double regularize = 0.0;  // m/N on every hard constraint
  std::vector<double> sweep_mass_ratios;
  double sweep_dt_min = 1e-5;
  double sweep_dt_max = 0.5;
  int sweep_per_decade = 8;
  int sweep_steps = 300;
  int sweep_links = 10;
};

// Kinetic + potential + spring_energy, J.
double total_energy(const Particles& particles, const Scene& scene);

// The step of `scene` with --method, --regularize, --compression and K_g on or off.
StableSettings settings_for(const Scene& scene, const CommonOptions& options, const LabOptions& lab,
                            bool geometric_stiffness);

// The experiment: for each --sweep-mass-ratios ratio, the heavy chain with and
// without K_g at log-spaced dt from --sweep-dt-min upwards until the first
// unstable one (the scans shared among the OpenMP threads) -> OUT/stability.csv,
// OUT/stability_runs.csv and the table on the terminal (its first line naming
// `lab_name`). Throws InputError for a dt range or --steps it cannot run.
int run_sweep(const char* lab_name, const CommonOptions& options, const LabOptions& lab);

}  // namespace cl::lab09
