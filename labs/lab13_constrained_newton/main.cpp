// lab13_constrained_newton: the compliant implicit-Euler step by Newton's
// method on the constrained system (x and λ), down to hard springs; lab 06's
// Newton and PD on the same scene for comparison.
//   default        run the scene's steps: per_step.csv, iterations.csv (every
//                  iteration of every step) and the run summary
//   --convergence  one step to its converged result against k, per method,
//                  start and warm start: convergence.csv, crossover.csv
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "../lab06_projective_dynamics/experiments.h"
#include "../lab06_projective_dynamics/simulation.h"
#include "common/cli.h"
#include "common/csv.h"
#include "common/driver.h"
#include "common/output.h"
#include "common/sparse.h"
#include "common/summary.h"
#include "experiments.h"

namespace {

using cl::lab13::LabOptions;
constexpr const char* kLab = CL_LAB_NAME;

cl::Scene load(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  if (!lab.stiffness.empty()) cl::lab13::set_stiffness(scene, cl::lab13::parse_stiffness("--stiffness", lab.stiffness));
  if (options.method != "constrained-newton") {
    cl::require_finite_springs(scene, "lab 06's " + options.method +
                                          " minimises finite springs' energy (use --method constrained-newton)");
  }
  return scene;
}

// Lab 06's Newton or PD on the same scene, for comparison.
int run_lab06(const cl::CommonOptions& options, cl::Scene& scene) {
  cl::lab06::Solver solver(cl::lab06::problem_of(scene), options.method == "pd" ? cl::lab06::Method::kProjectiveDynamics
                                                                               : cl::lab06::Method::kNewton);
  cl::lab06::StepSettings settings;
  settings.gravity = scene.gravity;
  settings.iterations = options.iterations;
  const cl::FrameOutput output =
      cl::frame_output(options, kLab, scene, "per_step.csv", cl::lab06::step_columns(), options.method);
  const cl::lab06::RunResult result = cl::lab06::run_steps(scene.particles, solver, settings, scene.steps, nullptr, output);
  const cl::StrainStats strain = cl::strain_stats(scene.particles.x, scene.springs);
  std::printf("%s: scene %s, %s (lab 06), K = %d, %d steps of %.4g s\n", kLab, scene.name.c_str(),
              options.method.c_str(), options.iterations, scene.steps, scene.dt);
  if (!result.problem.empty()) cl::print_stopped("DIVERGED", "step", result.problem_step, scene.dt, result.problem);
  std::printf("  max strain %.3e; %lld iterations\n", strain.max, result.iterations_done);
  cl::print_time(result.seconds, result.steps_done, "step");
  std::printf("\n");
  cl::print_trajectory_note(options, "step");
  if (!options.summary.empty()) {
    cl::RunSummary summary = cl::stepping_summary(kLab, options.method, scene, scene.particles, strain, result.seconds);
    summary.iterations = options.iterations;
    summary.extra["iterations_done"] = result.iterations_done;
    cl::add_total_energy(summary, result.energy_end, result.energy_start);
    cl::add_divergence(summary, result.problem, "diverged_at_step", result.problem_step);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

int run_steps(const cl::CommonOptions& options, LabOptions lab) {
  cl::Scene scene = load(options, lab);
  if (!options.out.empty()) cl::ensure_directory(options.out);
  if (options.method != "constrained-newton") return run_lab06(options, scene);
  cl::lab13::Solver solver(scene.particles.inv_mass, scene.springs, scene.dt);
  cl::lab13::Settings& settings = lab.settings;
  settings.gravity = scene.gravity;
  settings.iterations = options.iterations;
  cl::CsvTable table({"step", "iteration", "force_error", "constraint_error", "merit", "alpha", "backtracks",
                      "seconds"});
  const cl::lab13::RunIterationCallback on_iteration = [&](int step, const cl::lab13::IterationRecord& r) {
    table.add_row({static_cast<long long>(step), static_cast<long long>(r.iteration), r.force_error,
                   r.constraint_error, r.merit, r.alpha, static_cast<long long>(r.backtracks), r.seconds});
  };
  std::vector<int> iterations;
  std::vector<double> force_errors, constraint_errors;
  std::vector<int> backtracks;
  const cl::lab13::RunStepCallback on_step = [&](int, const cl::lab13::StepReport& r) {
    iterations.push_back(r.iterations_done);
    force_errors.push_back(r.force_error);
    constraint_errors.push_back(r.constraint_error);
    backtracks.push_back(r.backtracks);
  };
  const cl::FrameOutput output =
      cl::frame_output(options, kLab, scene, "per_step.csv", cl::lab13::step_columns(), options.method);
  cl::Particles& particles = scene.particles;
  const cl::lab13::RunResult result = cl::lab13::run_steps(
      particles, solver, settings, scene.steps, options.out.empty() ? nullptr : on_iteration, output, on_step);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  std::printf("%s: scene %s, %s (%s), start %s, warm %s, K = %d, tolerance %g, %d steps of %.4g s\n", kLab,
              scene.name.c_str(), options.method.c_str(), solver.all_compliant() ? "schur" : "kkt",
              cl::lab13::start_name(settings.start), cl::lab13::warm_name(settings.warm), options.iterations,
              settings.tolerance, scene.steps, scene.dt);
  if (!result.problem.empty()) {
    cl::print_stopped(result.step_failed ? "STOPPED" : "DIVERGED", "step", result.problem_step, scene.dt,
                      result.problem);
  }
  std::printf("  max strain %.3e; %lld iterations (%.2f per step), %d backtracks, %d failed decreases, "
              "%d fallbacks to dropped compression, %d exact rescues, %d steps not converged\n",
              strain.max, result.iterations_done,
              result.steps_done ? static_cast<double>(result.iterations_done) / result.steps_done : 0.0,
              result.backtracks, result.failed_decreases, result.fallbacks, result.exact_rescues,
              result.unconverged_steps);
  cl::print_time(result.seconds, result.steps_done, "step", static_cast<double>(result.iterations_done), "iteration");
  std::printf("\n");
  cl::print_trajectory_note(options, "step");
  if (!options.out.empty()) table.write(cl::join_path(options.out, "iterations.csv"));
  if (!options.summary.empty()) {
    cl::RunSummary summary = cl::stepping_summary(kLab, options.method, scene, particles, strain, result.seconds);
    summary.iterations = options.iterations;
    summary.extra["start"] = cl::lab13::start_name(settings.start);
    summary.extra["warm"] = cl::lab13::warm_name(settings.warm);
    summary.extra["tolerance"] = settings.tolerance;
    summary.extra["compression"] = settings.compression == cl::lab09::Compression::kDrop ? "drop" : "keep";
    summary.extra["linear_solver"] = solver.all_compliant() ? "schur" : "kkt";
    summary.extra["iterations_done"] = result.iterations_done;
    summary.extra["backtracks"] = result.backtracks;
    summary.extra["failed_decreases"] = result.failed_decreases;
    summary.extra["fallbacks"] = result.fallbacks;
    summary.extra["exact_rescues"] = result.exact_rescues;
    summary.extra["unconverged_steps"] = result.unconverged_steps;
    summary.extra["iterations_per_step"] = iterations;
    summary.extra["force_error_per_step"] = force_errors;
    summary.extra["constraint_error_per_step"] = constraint_errors;
    summary.extra["backtracks_per_step"] = backtracks;
    cl::add_total_energy(summary, result.energy_end, result.energy_start);
    cl::add_divergence(summary, result.problem, "diverged_at_step", result.problem_step);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 13: the implicit-Euler step by Newton's method on the constrained system (x and lambda), from soft "
      "springs to hard ones. Runs a scene, or (--convergence) one step of it to convergence against k.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options =
      cl::lab_defaults("pd-curtain-16", "constrained-newton", {"constrained-newton", "newton", "pd"});
  options.iterations = 10;
  cl::add_common_options(app, options, cl::kFlagScene | cl::kFlagMethod | cl::kFlagIterations | cl::kFlagDt |
                                           cl::kFlagSteps | cl::kFlagOut | cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  std::string start = "x", warm = "forces", compression = "keep";
  app.add_option("--start", start, "constrained-newton's first iterate: x (the step's start) or prediction (y)")
      .one_of({"x", "prediction"}).capture_default_str().only_for_methods({"constrained-newton"});
  app.add_option("--warm", warm, "constrained-newton's first multipliers: forces (the springs' at the start) or zero")
      .one_of({"forces", "zero"}).capture_default_str().only_for_methods({"constrained-newton"});
  app.add_option("--tolerance", lab.settings.tolerance,
                 "constrained-newton: stop once the force and constraint errors are both below this (0: every iteration)")
      .non_negative().capture_default_str().only_for_methods({"constrained-newton"});
  app.add_option("--stiffness", lab.stiffness, "every spring's stiffness, N/m, or inf (hard); default: the scene's");
  app.add_option("--compression", compression,
                 "compressed springs in K_g: keep (exact; dropped where not definite) or drop (always)")
      .one_of({"drop", "keep"}).capture_default_str().only_for_methods({"constrained-newton"});
  app.add_flag("--convergence", lab.convergence, "one step to convergence against k: convergence.csv, crossover.csv");
  app.add_option("--sweep-scenes", lab.sweep_scenes, "--convergence: the scenes (default: --scene)").delimiter(',');
  app.add_option("--stiffnesses", lab.stiffnesses, "--convergence: the stiffnesses, N/m or inf").delimiter(',')
      .capture_default_str();
  app.add_option("--starts", lab.starts, "--convergence: constrained-newton's first iterates (x, prediction)")
      .delimiter(',').capture_default_str();
  app.add_option("--warms", lab.warms, "--convergence: constrained-newton's warm starts (forces, zero)")
      .delimiter(',').capture_default_str();
  app.add_option("--warmup", lab.warmup, "--convergence: constrained Newton steps before the measured one")
      .range(0, 100000).capture_default_str();
  app.add_option("--newton-cap", lab.newton_cap, "--convergence: the most Newton iterations (both Newtons)")
      .range(1, 100000).capture_default_str();
  app.add_option("--pd-cap", lab.pd_cap, "--convergence: the most PD iterations").range(1, 1000000).capture_default_str();
  return cl::run_main(app, argc, argv, [&] {
    // CHOLMOD's BLAS on one thread: the solves are small, OpenBLAS's idle
    // threads spin (half of a 32² run's time went to sched_yield), and the
    // experiment times serial methods side by side, as the bench does.
    cl::set_blas_threads(1);
    lab.settings.start = cl::lab13::start_from_name(start);
    lab.settings.warm = cl::lab13::warm_from_name(warm);
    lab.settings.compression = compression == "keep" ? cl::lab09::Compression::kKeep : cl::lab09::Compression::kDrop;
    if (!lab.stiffness.empty()) cl::lab13::parse_stiffness("--stiffness", lab.stiffness);
    if (!lab.convergence && !lab.sweep_scenes.empty()) throw cl::InputError("--sweep-scenes: only with --convergence");
    if (lab.convergence) {
      if (!lab.stiffness.empty()) throw cl::InputError("--stiffness: --convergence sweeps --stiffnesses instead");
      return cl::lab13::run_convergence(kLab, CL_LAB_SCENE_DIR, options, lab);
    }
    return run_steps(options, lab);
  });
}
