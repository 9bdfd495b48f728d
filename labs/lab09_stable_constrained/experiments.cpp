#include "experiments.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Eigenvalues>

#include "common/csv.h"
#include "common/driver.h"
#include "common/health.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/timer.h"
#include "step.h"

namespace cl::lab09 {

double total_energy(const Particles& particles, const Scene& scene) {
  return cl::kinetic_energy(particles) + cl::potential_energy(particles, scene.gravity) +
         spring_energy(particles.x, scene.springs);
}

StableSettings settings_for(const Scene& scene, const CommonOptions& options, const LabOptions& lab,
                            bool geometric_stiffness) {
  StableSettings settings;
  settings.step.dt = scene.dt;
  settings.step.gravity = scene.gravity;
  settings.step.method = options.method == "kkt" ? cl::lab07::Method::kKkt : cl::lab07::Method::kSchur;
  settings.step.regularization = lab.regularize;
  settings.geometric_stiffness = geometric_stiffness;
  settings.compression = lab.compression == "keep" ? Compression::kKeep : Compression::kDrop;
  return settings;
}

namespace {

// The heavy chain of the experiment (see stable_step.h: heavy_chain).
constexpr double kLinkLength = 0.1;  // m
constexpr double kBeadMass = 1.0;    // kg
constexpr double kKick = 0.01;       // m/s
// A sweep run is unstable once a link turns this many times faster than the kick.
constexpr double kTransverseGrowth = 100.0;

// Empty when healthy: finite, strain below cl::kUnstableStrain, energy not
// risen by more than the scene's scale (the step only loses energy).
std::string check_health(const cl::Particles& particles, const cl::Scene& scene, double energy_start,
                         double scale) {
  std::string problem = cl::health_problem(particles, cl::strain_stats(particles.x, scene.springs));
  if (!problem.empty()) return problem;
  const double rise = total_energy(particles, scene) - energy_start;
  return cl::energy_rise_problem(rise, scale);
}

struct SweepRun {
  double dt = 0.0;
  int steps_done = 0;
  bool stable = false;
  double max_transverse_speed = 0.0;
  double seconds = 0.0;
  std::string status;
};

// Runs the chain for `steps` steps of dt; stable when every step solves, the
// state stays healthy and no link turns faster than kTransverseGrowth × kick.
SweepRun sweep_run(const cl::Scene& chain, const StableSettings& base, double dt, int steps) {
  SweepRun run;
  run.dt = dt;
  cl::Scene scene = chain;
  scene.dt = dt;
  StableSettings settings = base;
  settings.step.dt = dt;
  cl::Particles& particles = scene.particles;
  const cl::MovableMap map = cl::make_movable_map(particles.inv_mass);
  const double energy_start = total_energy(particles, scene);
  const double scale = cl::energy_scale(particles, scene.gravity, dt);
  const double limit = kTransverseGrowth * kKick;
  Eigen::VectorXd lambda;
  const cl::Timer timer;
  run.status = "stable";
  for (int s = 1; s <= steps; ++s) {
    const StableStepResult result = stable_step(particles, scene.springs, map, settings, lambda);
    if (!result.ok) {
      run.status = "failed at step " + std::to_string(s) + ": " + result.problem;
      break;
    }
    lambda = result.lambda;
    const std::string problem = check_health(particles, scene, energy_start, scale);
    if (!problem.empty()) {
      run.status = "diverged at step " + std::to_string(s) + ": " + problem;
      break;
    }
    const double transverse = max_transverse_speed(particles, scene.springs);
    run.max_transverse_speed = std::max(run.max_transverse_speed, transverse);
    run.steps_done = s;
    if (transverse > limit) {
      char text[128];
      std::snprintf(text, sizeof text, "transverse speed %.3g m/s > %.3g m/s at step %d", transverse, limit, s);
      run.status = text;
      break;
    }
  }
  run.stable = run.status == "stable";
  run.seconds = timer.seconds();
  return run;
}

// The largest step at which symplectic Euler on the chain's transverse
// vibrations is stable, 2/ω_max: what lab 07's step (no K_g) should reach.
// Transverse displacements y of the movable particles, link p of tension T_p
// adds T_p (y_p − y_{p−1})² / (2ℓ) to the energy; ω² = eig(M⁻¹K).
double predicted_limit(const cl::Scene& chain) {
  const Eigen::Index n = chain.particles.size() - 1;  // particle 0 is the pin
  Eigen::MatrixXd stiffness = Eigen::MatrixXd::Zero(n, n);
  double below = 0.0;  // weight hanging below the current link
  std::vector<double> tension(static_cast<std::size_t>(n));
  for (Eigen::Index p = n; p >= 1; --p) {
    below += chain.gravity.norm() / chain.particles.inv_mass[p];
    tension[static_cast<std::size_t>(p - 1)] = below;
  }
  for (Eigen::Index p = 1; p <= n; ++p) {
    const double k = tension[static_cast<std::size_t>(p - 1)] / kLinkLength;
    stiffness(p - 1, p - 1) += k;
    if (p >= 2) {
      stiffness(p - 2, p - 2) += k;
      stiffness(p - 1, p - 2) -= k;
      stiffness(p - 2, p - 1) -= k;
    }
  }
  Eigen::VectorXd root_w(n);
  for (Eigen::Index p = 1; p <= n; ++p) root_w[p - 1] = std::sqrt(chain.particles.inv_mass[p]);
  const Eigen::MatrixXd scaled = root_w.asDiagonal() * stiffness * root_w.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(scaled, Eigen::EigenvaluesOnly);
  return 2.0 / std::sqrt(solver.eigenvalues().maxCoeff());
}

struct Scan {
  double ratio = 1.0;
  bool geometric_stiffness = false;
  std::vector<SweepRun> runs;
  double largest_stable = 0.0;  // 0: not even the smallest dt
  double first_unstable = 0.0;  // 0: none up to the largest dt
};

}  // namespace

int run_sweep(const char* lab_name, const CommonOptions& options, const LabOptions& lab) {
  if (lab.sweep_dt_max <= lab.sweep_dt_min) {
    throw cl::InputError("--sweep-dt-max: must be larger than --sweep-dt-min");
  }
  cl::start_run(options);
  const int steps = options.steps >= 0 ? options.steps : lab.sweep_steps;
  if (steps < 1) throw cl::InputError("--steps: a sweep needs at least 1 step");

  // Log-spaced steps from dt_min to dt_max, both included.
  std::vector<double> dts;
  const double decades = std::log10(lab.sweep_dt_max / lab.sweep_dt_min);
  const int count = std::max(1, static_cast<int>(std::ceil(decades * lab.sweep_per_decade)));
  for (int k = 0; k <= count; ++k) dts.push_back(lab.sweep_dt_min * std::pow(10.0, decades * k / count));
  dts.back() = lab.sweep_dt_max;  // exactly, not through pow's round-off

  std::vector<Scan> scans;
  for (const double ratio : lab.sweep_mass_ratios) {
    for (const bool on : {false, true}) scans.push_back({ratio, on, {}, 0.0, 0.0});
  }
  // The scans are independent: shared among the OpenMP threads, in order.
  cl::run_shared(cl::costliest_first(std::vector<double>(scans.size(), 1.0)), [&](std::size_t k) {
    Scan& scan = scans[k];
    const cl::Scene chain = heavy_chain(lab.sweep_links, kLinkLength, kBeadMass, scan.ratio,
                                                   cl::kInfiniteStiffness, kKick);
    const StableSettings base = settings_for(chain, options, lab, scan.geometric_stiffness);
    // Upwards until the first unstable step size.
    for (const double dt : dts) {
      scan.runs.push_back(sweep_run(chain, base, dt, steps));
      if (!scan.runs.back().stable) {
        scan.first_unstable = dt;
        break;
      }
      scan.largest_stable = dt;
    }
  });

  cl::CsvTable limits({"mass_ratio", "geometric_stiffness", "method", "compression", "links", "steps",
                       "largest_stable_dt", "first_unstable_dt", "dt_min", "dt_max", "predicted_dt_without",
                       "seconds"});
  cl::CsvTable runs({"mass_ratio", "geometric_stiffness", "method", "dt", "steps_done", "stable",
                     "max_transverse_speed", "seconds", "status"});
  std::printf("%s: heavy chain of %d hard links of %.3g m, %.3g kg beads, the bottom mass = ratio x bead, kick "
              "%.3g m/s; %s; %d steps per run; unstable: a failed solve, unhealthy, or a link turning faster than "
              "%.3g m/s\n",
              lab_name, lab.sweep_links, kLinkLength, kBeadMass, kKick, options.method.c_str(), steps,
              kTransverseGrowth * kKick);
  std::printf("%10s %6s %18s %18s %22s %9s\n", "mass_ratio", "K_g", "largest_stable_dt", "first_unstable_dt",
              "2/omega_max (no K_g)", "seconds");
  for (const Scan& scan : scans) {
    const cl::Scene chain =
        heavy_chain(lab.sweep_links, kLinkLength, kBeadMass, scan.ratio, cl::kInfiniteStiffness, kKick);
    const double predicted = predicted_limit(chain);
    double seconds = 0.0;
    const char* mode = scan.geometric_stiffness ? "on" : "off";
    for (const SweepRun& run : scan.runs) {
      seconds += run.seconds;
      runs.add_row({scan.ratio, std::string(mode), options.method, run.dt, static_cast<long long>(run.steps_done),
                    static_cast<long long>(run.stable ? 1 : 0), run.max_transverse_speed, run.seconds, run.status});
    }
    limits.add_row({scan.ratio, std::string(mode), options.method, lab.compression,
                    static_cast<long long>(lab.sweep_links), static_cast<long long>(steps),
                    cl::cell_if(scan.largest_stable > 0.0, scan.largest_stable),
                    cl::cell_if(scan.first_unstable > 0.0, scan.first_unstable), dts.front(), dts.back(), predicted,
                    seconds});
    char largest[32], first[32];
    std::snprintf(largest, sizeof largest, scan.largest_stable > 0.0 ? "%.4g" : "< %.4g",
                  scan.largest_stable > 0.0 ? scan.largest_stable : dts.front());
    std::snprintf(first, sizeof first, scan.first_unstable > 0.0 ? "%.4g" : "none <= %.4g",
                  scan.first_unstable > 0.0 ? scan.first_unstable : dts.back());
    std::printf("%10.4g %6s %18s %18s %22.4g %9.3f\n", scan.ratio, mode, largest, first, predicted, seconds);
  }
  if (!options.out.empty()) {
    limits.write(cl::join_path(options.out, "stability.csv"));
    runs.write(cl::join_path(options.out, "stability_runs.csv"));
  }
  return 0;
}

}  // namespace cl::lab09
