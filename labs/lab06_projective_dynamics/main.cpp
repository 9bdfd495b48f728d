// lab06_projective_dynamics: implicit Euler by projective dynamics (one
// factorization per scene, K cheap iterations per step) or by Newton's method
// (a fresh factorization per iteration) on the same objective.
//   default          run the scene's steps: per_step.csv and the run summary
//   --convergence    one step, both methods, to the minimum: convergence.csv
//                    (objective gap against iteration and wall time) and
//                    crossover.csv (time to a relative error of 1e-3 and 1e-6)
//                    (experiments.cpp)
#include <algorithm>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/driver.h"
#include "common/live.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "experiments.h"
#include "projective_dynamics.h"
#include "simulation.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;
using cl::lab06::LabOptions;
cl::LiveOptions live;  // --live [PORT]: the scene steps beside a page in the browser (./course live)

cl::lab06::Method method_of(const std::string& name) {
  return name == "newton" ? cl::lab06::Method::kNewton : cl::lab06::Method::kProjectiveDynamics;
}

// cl::describe without the triangles: this lab's objective has springs alone.
std::string describe_springs(const cl::Scene& scene) {
  std::ostringstream text;
  text << scene.name << " (" << scene.particles.size() << " particles, " << scene.springs.size() << " springs)";
  return text.str();
}

// ------------------------------------------------------------------ a run of steps

int run_steps(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::lab06::load_finite_scene(kLab, CL_LAB_SCENE_DIR, options, lab, options.scene);
  cl::start_run(options);
  const cl::lab06::Method method = method_of(options.method);
  cl::lab06::Solver solver(cl::lab06::problem_of(scene), method);
  cl::lab06::StepSettings settings;
  settings.gravity = scene.gravity;
  settings.iterations = options.iterations;
  settings.tolerance = lab.tolerance;

  if (live.on) {  // k, dt and a pin or a held particle change A: the solver is built again (refactored)
    cl::refuse_run_flags(options, "not with --live (the page shows every step)", "");
    const double k = scene.springs.empty() ? 1.0 : scene.springs.front().stiffness;
    cl::LiveRun run{kLab, options.method, {{"K", "iterations", 1, 100, 1.0 * options.iterations, true},
                                           {"dt", "s", 1e-4, 0.05, scene.dt}, {"k", "N/m", 1, 1e6, k}}};
    std::vector<cl::Spring> springs = scene.springs;
    std::optional<cl::lab06::Solver> live_solver;
    cl::BuiltFor built;  // A depends on the masses (pins, held particles), dt and k; not on K
    run.changed = [&](const cl::Knobs& knobs) -> std::string {
      if (!built.update(scene.particles.inv_mass, {knobs[1], knobs[2]})) return "";
      for (cl::Spring& spring : springs) spring.stiffness = knobs[2];
      live_solver.emplace(cl::lab06::make_problem(scene.particles.inv_mass, springs, knobs[1]), method);
      return "A, factored again";
    };
    run.step = [&](const cl::Knobs& knobs) {
      settings.iterations = knobs.integer(0);
      const cl::lab06::StepReport report = live_solver->step(scene.particles, settings);
      return cl::StepVerdict{report.problem, true, report.seconds};
    };
    run.energy_name = "total energy";  // kinetic + potential + the springs' elastic
    run.energy = [&](const cl::Particles& state) {
      return cl::kinetic_energy(state) + cl::potential_energy(state, scene.gravity) +
             cl::lab06::spring_energy(state.x, springs);
    };
    return cl::run_live(scene, live, run, options.summary);
  }
  cl::FrameOutput output =
      cl::frame_output(options, kLab, scene, "per_step.csv", cl::lab06::step_columns(), options.method);
  cl::Particles& particles = scene.particles;
  const cl::lab06::RunResult result = cl::lab06::run_steps(particles, solver, settings, scene.steps, nullptr, output);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  const bool diverged = !result.problem.empty();

  std::printf("%s: scene %s, %s, K = %d%s, %d steps of %.4g s\n", kLab, describe_springs(scene).c_str(),
              cl::lab06::method_name(method), options.iterations,
              lab.tolerance > 0.0 ? (", tolerance " + cl::format_double(lab.tolerance)).c_str() : "", scene.steps,
              scene.dt);
  std::printf("  factorizations: %d (%.3e s)\n", solver.factorizations(), solver.factor_seconds());
  if (diverged) {
    cl::print_stopped("DIVERGED", "step", result.problem_step, scene.dt, result.problem);
  } else {
    // A spring of rest length 0 has no strain: strain_stats counts its length (m).
    const auto zero_rest = std::count_if(scene.springs.begin(), scene.springs.end(),
                                         [](const cl::Spring& spring) { return spring.rest_length == 0.0; });
    if (zero_rest > 0 && zero_rest == static_cast<std::ptrdiff_t>(scene.springs.size())) {
      std::printf("  final:   objective %.6e J, max spring length %.3e m, rms %.3e m (rest length 0: no strain)\n",
                  result.objective, strain.max, strain.rms);
    } else {
      std::printf("  final:   objective %.6e J, max strain %.3e, rms %.3e%s\n", result.objective, strain.max,
                  strain.rms, zero_rest > 0 ? " (a spring of rest length 0 counts its length, m)" : "");
    }
    std::printf("  energy:  total %.6e J (start %.6e J)\n", result.energy_end, result.energy_start);
  }
  if (result.failed_decreases > 0) {
    std::printf("  newton: %d line search(es) found no decrease of the objective (see failed_decreases in the CSV)\n",
                result.failed_decreases);
  }
  std::printf("  iterations: %lld in %d steps; time %.3e s: %.3e s per step", result.iterations_done,
              result.steps_done, result.seconds, result.steps_done > 0 ? result.seconds / result.steps_done : 0.0);
  if (result.iterations_done > 0) {
    std::printf(", %.3e s per iteration", result.seconds / static_cast<double>(result.iterations_done));
  }
  std::printf("\n");

  cl::print_trajectory_note(options, "step");
  if (!options.summary.empty()) {
    cl::RunSummary summary =
        cl::stepping_summary(kLab, cl::lab06::method_name(method), scene, particles, strain, result.seconds);
    summary.iterations = options.iterations;
    summary.extra["objective"] = result.objective;
    summary.extra["factorizations"] = solver.factorizations();
    summary.extra["iterations_done"] = result.iterations_done;
    summary.extra["tolerance"] = lab.tolerance;
    summary.extra["factor_seconds"] = solver.factor_seconds();
    summary.extra["failed_decreases"] = result.failed_decreases;
    summary.extra["rms_strain_error"] = strain.rms;
    cl::add_total_energy(summary, result.energy_end, result.energy_start);
    cl::add_divergence(summary, result.problem, "diverged_at_step", result.problem_step);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  if (lab.convergence) {
    cl::refuse_run_flags(options, "only for one run (not with --convergence)",
                         "--convergence writes CSV files, not a run summary");
    return cl::lab06::run_convergence(kLab, CL_LAB_SCENE_DIR, options, lab);
  }
  if (!lab.sweep_scenes.empty()) throw cl::InputError("--sweep-scenes: only with --convergence");
  return run_steps(options, lab);
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 06: projective dynamics against Newton on the implicit-Euler objective. Runs a scene and "
      "writes per-step objective, iterations, time and strain and a summary; or (--convergence) one "
      "step of each method to its minimum and writes the convergence curves.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("pd-curtain-16", "pd", {"pd", "newton"});
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagMethod | cl::kFlagIterations | cl::kFlagDt | cl::kFlagSteps |
                             cl::kFlagOut | cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  cl::add_live_option(app, live);
  app.add_option("--tolerance", lab.tolerance,
                 "stop a step's iterations once the objective's relative decrease falls below this (0: run all K)")
      .non_negative()
      .capture_default_str();
  app.add_option("--stiffness", lab.stiffness, "replace every spring's stiffness (N/m)")
      .positive();
  app.add_flag("--convergence", lab.convergence,
               "one step of each method to the minimum: convergence.csv and crossover.csv");
  app.add_option("--warmup", lab.warmup, "--convergence: PD steps (K = --iterations) before the measured step")
      .range(0, 1'000'000)
      .capture_default_str();
  app.add_option("--pd-cap", lab.pd_cap, "--convergence: the most PD iterations")
      .range(1, 100'000'000)
      .capture_default_str();
  app.add_option("--newton-cap", lab.newton_cap, "--convergence: the most Newton iterations")
      .range(1, 1'000'000)
      .capture_default_str();
  app.add_option("--stop-gap", lab.stop_gap,
                 "--convergence: end the PD run once its relative objective error (g - g*)/g*, g* Newton's "
                 "minimum, is this small")
      .finite_in(0.0, 1.0)
      .capture_default_str();
  app.add_option("--max-seconds", lab.max_seconds,
                 "--convergence: end a run after this many seconds of wall time (0: no limit)")
      .non_negative()
      .capture_default_str();
  app.add_option("--sweep-scenes", lab.sweep_scenes, "--convergence: the scenes (default: --scene)")
      .delimiter(',');
  app.modes({{"--convergence", {"--warmup", "--pd-cap", "--newton-cap", "--stop-gap", "--max-seconds", "--sweep-scenes"}}},
            {"--method", "--tolerance", "--steps", "--live"});
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
