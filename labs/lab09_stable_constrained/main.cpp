// lab09_stable_constrained: lab 07's constrained step with the geometric
// stiffness K_g of the distance constraints (--geometric-stiffness on|off),
// solved as one KKT system (--method kkt) or by a Schur complement (--method
// schur). Per-frame constraint error, transverse speed and energy
// (per_frame.csv) and the run summary with the multipliers; and one experiment:
//   --sweep-mass-ratios 1,10,...   largest stable dt of a heavy chain against its
//                                  mass ratio, with and without K_g -> stability.csv,
//                                  stability_runs.csv
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "common/cli.h"
#include "common/csv.h"
#include "common/driver.h"
#include "common/frame_loop.h"
#include "common/health.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "common/timer.h"
#include "geometric_stiffness.h"
#include "stable_step.h"
#include "step.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;

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

// The heavy chain of the experiment (see stable_step.h: heavy_chain).
constexpr double kLinkLength = 0.1;  // m
constexpr double kBeadMass = 1.0;    // kg
constexpr double kKick = 0.01;       // m/s
// A sweep run is unstable once a link turns this many times faster than the kick.
constexpr double kTransverseGrowth = 100.0;

std::string describe_constraints_and_masses(const cl::Scene& scene) {
  std::ostringstream text;
  int hard = 0;
  for (const cl::Spring& s : scene.springs) hard += std::isfinite(s.stiffness) ? 0 : 1;
  double lightest = 0.0, heaviest = 0.0;
  for (Eigen::Index p = 0; p < scene.particles.size(); ++p) {
    const double w = scene.particles.inv_mass[p];
    if (!(w > 0.0)) continue;
    lightest = lightest == 0.0 ? 1.0 / w : std::min(lightest, 1.0 / w);
    heaviest = std::max(heaviest, 1.0 / w);
  }
  text << scene.name << " (" << scene.particles.size() << " particles, " << scene.springs.size() << " springs, "
       << hard << " of them hard";
  if (lightest > 0.0) text << ", mass ratio " << heaviest / lightest;
  text << ")";
  return text.str();
}

double total_energy(const cl::Particles& particles, const cl::Scene& scene) {
  return cl::kinetic_energy(particles) + cl::potential_energy(particles, scene.gravity) +
         cl::lab09::spring_energy(particles.x, scene.springs);
}

// Empty when healthy: finite, strain below cl::kUnstableStrain, energy not
// risen by more than the scene's scale (the step only loses energy).
std::string check_health(const cl::Particles& particles, const cl::Scene& scene, double energy_start,
                         double scale) {
  std::string problem = cl::health_problem(particles, cl::strain_stats(particles.x, scene.springs));
  if (!problem.empty()) return problem;
  const double rise = total_energy(particles, scene) - energy_start;
  return cl::energy_rise_problem(rise, scale);
}

cl::lab09::StableSettings settings_for(const cl::Scene& scene, const cl::CommonOptions& options,
                                       const LabOptions& lab, bool geometric_stiffness) {
  cl::lab09::StableSettings settings;
  settings.step.dt = scene.dt;
  settings.step.gravity = scene.gravity;
  settings.step.method = options.method == "kkt" ? cl::lab07::Method::kKkt : cl::lab07::Method::kSchur;
  settings.step.regularization = lab.regularize;
  settings.geometric_stiffness = geometric_stiffness;
  settings.compression = lab.compression == "keep" ? cl::lab09::Compression::kKeep : cl::lab09::Compression::kDrop;
  return settings;
}

// ------------------------------------------------------------------ one run

int run_one(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  if (!options.out.empty()) cl::ensure_directory(options.out);
  const cl::lab09::StableSettings settings = settings_for(scene, options, lab, lab.geometric_stiffness == "on");

  cl::Particles& particles = scene.particles;
  const cl::MovableMap map = cl::make_movable_map(particles.inv_mass);
  const double energy_start = total_energy(particles, scene);
  const double scale = cl::energy_scale(particles, scene.gravity, scene.dt);
  const auto m = static_cast<Eigen::Index>(scene.springs.size());

  Eigen::VectorXd lambda;  // the previous step's multipliers (none before the first step)
  double worst_transverse = cl::lab09::max_transverse_speed(particles, scene.springs);
  auto step = [&](int) -> cl::StepVerdict {
    const cl::lab09::StableStepResult result = cl::lab09::stable_step(particles, scene.springs, map, settings, lambda);
    if (!result.ok) return {"failed: " + result.problem, false};
    lambda = result.lambda;
    worst_transverse = std::max(worst_transverse, cl::lab09::max_transverse_speed(particles, scene.springs));
    return {};
  };
  auto measure = [&](int, double seconds) {
    const double kinetic = cl::kinetic_energy(particles);
    const double potential = cl::potential_energy(particles, scene.gravity);
    const double elastic = cl::lab09::spring_energy(particles.x, scene.springs);
    const bool known = lambda.size() == m && m > 0;
    return cl::FrameMeasure{cl::strain_stats(particles.x, scene.springs), kinetic + potential + elastic, {},
                            {cl::lab07::max_constraint_error(particles.x, scene.springs),
                             cl::lab09::max_transverse_speed(particles, scene.springs),
                             known ? cl::CsvCell{lambda.minCoeff()} : cl::CsvCell{std::string()},
                             known ? cl::CsvCell{lambda.maxCoeff()} : cl::CsvCell{std::string()}, kinetic, potential,
                             elastic, kinetic + potential + elastic, seconds},
                            {}};
  };
  const cl::FramePlan plan = cl::frame_plan(scene.steps, scene.dt, scale);
  cl::FrameOutput output = cl::frame_output(options, kLab, scene, "per_frame.csv",
                                            {"max_constraint_error", "max_transverse_speed", "min_lambda", "max_lambda",
                                             "kinetic", "potential", "spring_energy", "total_energy", "step_seconds"},
                                            options.method + ", K_g " + lab.geometric_stiffness);
  const cl::FrameLoopResult run = cl::run_frame_loop(particles, step, measure, plan, output);
  const int frames_done = run.frames_done;
  const int problem_frame = run.problem_frame;
  const double seconds = run.seconds;
  const std::string outcome = run.problem.empty() ? std::string() : run.status;  // "diverged: …" or "failed: …"

  const bool stopped = !outcome.empty();
  const bool finite = cl::all_finite(particles.x) && cl::all_finite(particles.v);
  const double final_error = cl::lab07::max_constraint_error(particles.x, scene.springs);
  const double final_transverse = cl::lab09::max_transverse_speed(particles, scene.springs);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  std::printf("%s: scene %s, %s, geometric stiffness %s (compression: %s), dt %.4g s, %d steps\n", kLab,
              describe_constraints_and_masses(scene).c_str(), options.method.c_str(), lab.geometric_stiffness.c_str(),
              lab.compression.c_str(), scene.dt, scene.steps);
  if (stopped) {
    cl::print_stopped("STOPPED", "step", problem_frame, scene.dt, outcome);
  }
  if (finite) {
    std::printf("  transverse speed: %.3e m/s at the end, %.3e m/s the most over the run\n", final_transverse,
                worst_transverse);
    std::printf("  max |phi| %.3e m at the end; max strain %.3e\n", final_error, strain.max);
    std::printf("  energy: %.6e J (start %.6e J)\n", total_energy(particles, scene), energy_start);
  }
  std::printf("  time %.3e s: %.3e s per step\n", seconds, seconds / std::max(1, frames_done));
  if (!cl::print_multipliers(lambda) && lambda.size() > 4) {
    std::printf("  multipliers from %.6g N to %.6g N (negative: tension)\n", lambda.minCoeff(), lambda.maxCoeff());
  }

  cl::print_trajectory_note(options, "frame");
  if (!options.summary.empty()) {
    cl::RunSummary summary = cl::stepping_summary(kLab, options.method, scene, particles, strain, seconds);
    summary.extra["geometric_stiffness"] = lab.geometric_stiffness;
    summary.extra["compression"] = lab.compression;
    summary.extra["multipliers"] = std::vector<double>(lambda.data(), lambda.data() + lambda.size());
    summary.extra["max_constraint_error"] = final_error;
    summary.extra["max_transverse_speed"] = worst_transverse;
    summary.extra["final_transverse_speed"] = final_transverse;
    summary.extra["regularization"] = lab.regularize;
    summary.extra["steps_done"] = frames_done;
    cl::add_total_energy(summary, total_energy(particles, scene), energy_start);
    cl::add_stop_outcome(summary, outcome, "failed", problem_frame);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

// ------------------------------------------------------------------ the stability experiment

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
SweepRun sweep_run(const cl::Scene& chain, const cl::lab09::StableSettings& base, double dt, int steps) {
  SweepRun run;
  run.dt = dt;
  cl::Scene scene = chain;
  scene.dt = dt;
  cl::lab09::StableSettings settings = base;
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
    const cl::lab09::StableStepResult result = cl::lab09::stable_step(particles, scene.springs, map, settings, lambda);
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
    const double transverse = cl::lab09::max_transverse_speed(particles, scene.springs);
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

int run_sweep(const cl::CommonOptions& options, const LabOptions& lab) {
  if (lab.sweep_dt_max <= lab.sweep_dt_min) {
    throw cl::InputError("--sweep-dt-max: must be larger than --sweep-dt-min");
  }
  if (!options.out.empty()) cl::ensure_directory(options.out);
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
    const cl::Scene chain = cl::lab09::heavy_chain(lab.sweep_links, kLinkLength, kBeadMass, scan.ratio,
                                                   cl::kInfiniteStiffness, kKick);
    const cl::lab09::StableSettings base = settings_for(chain, options, lab, scan.geometric_stiffness);
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
              kLab, lab.sweep_links, kLinkLength, kBeadMass, kKick, options.method.c_str(), steps,
              kTransverseGrowth * kKick);
  std::printf("%10s %6s %18s %18s %22s %9s\n", "mass_ratio", "K_g", "largest_stable_dt", "first_unstable_dt",
              "2/omega_max (no K_g)", "seconds");
  for (const Scan& scan : scans) {
    const cl::Scene chain =
        cl::lab09::heavy_chain(lab.sweep_links, kLinkLength, kBeadMass, scan.ratio, cl::kInfiniteStiffness, kKick);
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

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  if (lab.sweep_mass_ratios.empty()) return run_one(options, lab);
  cl::refuse_run_flags(options, "only for one run (not with --sweep-mass-ratios)",
                       "a sweep writes stability.csv, not a run summary");
  return run_sweep(options, lab);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Lab 09: stable constrained dynamics. Lab 07's step with the geometric stiffness of the distance "
               "constraints, solved as one KKT system or by a Schur complement; writes per-frame constraint error, "
               "transverse speed and energy and a summary with the multipliers. Or measures the largest stable "
               "dt of a heavy chain against its mass ratio, with and without the geometric stiffness.",
               CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("heavy-chain-1000", "schur", {"schur", "kkt"});
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagMethod | cl::kFlagDt | cl::kFlagSteps | cl::kFlagOut |
                             cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  app.add_option("--geometric-stiffness", lab.geometric_stiffness,
                 "add K_g to the step (on) or not (off: lab 07's step)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  app.add_option("--compression", lab.compression,
                 "compressed constraints (lambda > 0) in K_g: drop them (always SPD) or keep them (exact, may be "
                 "indefinite)")
      ->check(CLI::IsMember({"drop", "keep"}))
      ->capture_default_str();
  app.add_option("--regularize", lab.regularize,
                 "compliance (m/N) added to every hard constraint, as in lab 07 (e.g. 1e-9)")
      ->check(cl::finite_number(true));
  app.add_option("--sweep-mass-ratios", lab.sweep_mass_ratios,
                 "experiment: for each mass ratio (e.g. 1,10,100) find the largest stable dt of the heavy chain "
                 "with and without K_g; writes stability.csv and stability_runs.csv")
      ->delimiter(',')
      ->check(cl::finite_in(1e-6, 1e12));
  app.add_option("--sweep-dt-min", lab.sweep_dt_min, "experiment: the smallest dt tried (s)")
      ->check(cl::finite_in(1e-7, 10.0))
      ->capture_default_str();
  app.add_option("--sweep-dt-max", lab.sweep_dt_max, "experiment: the largest dt tried (s)")
      ->check(cl::finite_in(1e-7, 10.0))
      ->capture_default_str();
  app.add_option("--sweep-per-decade", lab.sweep_per_decade, "experiment: dt values per decade")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--sweep-links", lab.sweep_links, "experiment: links in the chain")
      ->check(CLI::Range(2, 10000))
      ->capture_default_str();
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
