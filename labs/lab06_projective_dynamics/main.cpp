// lab06_projective_dynamics: implicit Euler by projective dynamics (one
// factorization per scene, K cheap iterations per step) or by Newton's method
// (a fresh factorization per iteration) on the same objective.
//   default          run the scene's steps: per_step.csv and the run summary
//   --convergence    one step, both methods, to the minimum: convergence.csv
//                    (objective gap against iteration and wall time) and
//                    crossover.csv (time to a relative error of 1e-3 and 1e-6)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/csv.h"
#include "common/driver.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "common/timer.h"
#include "projective_dynamics.h"
#include "simulation.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;
constexpr double kTargets[] = {1e-2, 1e-3, 1e-6};  // relative objective errors (g − g*)/g*

struct LabOptions {
  double tolerance = 0.0;
  std::optional<double> stiffness;  // replaces every spring's stiffness
  bool convergence = false;
  int warmup = 0;
  int pd_cap = 3000;
  int newton_cap = 50;
  double stop_gap = 1e-9;           // the experiment ends PD at this relative error
  double max_seconds = 0.0;         // the experiment ends a run after this wall time (0: no limit)
  std::vector<std::string> sweep_scenes;
};

cl::lab06::Method method_of(const std::string& name) {
  return name == "newton" ? cl::lab06::Method::kNewton : cl::lab06::Method::kProjectiveDynamics;
}

// The scene with --stiffness applied; hard constraints are refused here,
// naming the spring (lab 07 is the lab for them).
cl::Scene load(const cl::CommonOptions& options, const LabOptions& lab, const std::string& name) {
  cl::CommonOptions one = options;
  one.scene = name;
  cl::Scene scene = cl::load_scene_for(one, CL_LAB_SCENE_DIR);
  for (std::size_t e = 0; e < scene.springs.size(); ++e) {
    cl::Spring& spring = scene.springs[e];
    if (lab.stiffness) spring.stiffness = *lab.stiffness;
    if (std::isinf(spring.stiffness)) {
      throw cl::InputError(scene.source + ": springs[" + std::to_string(e) + "] (particles " +
                           std::to_string(spring.i) + "-" + std::to_string(spring.j) +
                           ").stiffness: inf is a hard constraint; " + kLab +
                           " needs finite springs (lab 07 handles hard constraints), or pass --stiffness");
    }
  }
  return scene;
}

cl::lab06::Problem problem_of(const cl::Scene& scene) {
  return cl::lab06::make_problem(scene.particles.inv_mass, scene.springs, scene.dt);
}

// cl::describe without the triangles: this lab's objective has springs alone.
std::string describe_springs(const cl::Scene& scene) {
  std::ostringstream text;
  text << scene.name << " (" << scene.particles.size() << " particles, " << scene.springs.size() << " springs)";
  return text.str();
}

// ------------------------------------------------------------------ a run of steps

int run_steps(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = load(options, lab, options.scene);
  if (!options.out.empty()) cl::ensure_directory(options.out);
  const cl::lab06::Method method = method_of(options.method);
  cl::lab06::Solver solver(problem_of(scene), method);
  cl::lab06::StepSettings settings;
  settings.gravity = scene.gravity;
  settings.iterations = options.iterations;
  settings.tolerance = lab.tolerance;

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

// ------------------------------------------------------------------ the convergence experiment

struct Curve {
  std::string method;
  std::vector<cl::lab06::IterationRecord> records;
  double setup_seconds = 0.0;  // PD: the factorization, once per scene
  std::string problem;
  int failed_decreases = 0;
  bool converged = false;
  bool timed_out = false;
};

// One step of `method` from `start`, recording every iterate. Stops at `cap`
// iterations, after max_seconds of wall time (if > 0, setup included), or
// once (g − best_known)/best_known <= stop_gap, if best_known (a previous
// run's minimum) is finite.
Curve measure_step(cl::lab06::Solver& solver, const cl::Particles& start, const cl::lab06::StepSettings& base,
                   int cap, double best_known, double stop_gap, double max_seconds) {
  Curve curve;
  curve.method = cl::lab06::method_name(solver.method());
  curve.setup_seconds = solver.method() == cl::lab06::Method::kProjectiveDynamics ? solver.factor_seconds() : 0.0;
  cl::lab06::StepSettings settings = base;
  settings.iterations = cap;
  // Newton stops once the objective stops moving (at round-off); PD runs to
  // its cap or to stop_gap.
  settings.tolerance = solver.method() == cl::lab06::Method::kNewton ? 1e-15 : 0.0;
  cl::Particles particles = start;
  const cl::lab06::StepReport report =
      solver.step(particles, settings, [&](const cl::lab06::IterationRecord& record) {
        curve.records.push_back(record);
        if (max_seconds > 0.0 && record.seconds + curve.setup_seconds >= max_seconds) {
          curve.timed_out = true;
          return true;
        }
        return std::isfinite(best_known) && record.objective - best_known <= stop_gap * std::abs(best_known);
      });
  curve.problem = report.problem;
  curve.failed_decreases = report.failed_decreases;
  curve.converged = report.converged;
  return curve;
}

int run_convergence(const cl::CommonOptions& options, const LabOptions& lab) {
  std::vector<cl::Scene> scenes;
  for (const std::string& name : lab.sweep_scenes.empty() ? std::vector<std::string>{options.scene} : lab.sweep_scenes) {
    scenes.push_back(load(options, lab, name));
  }
  if (!options.out.empty()) cl::ensure_directory(options.out);
  cl::CsvTable curves({"scene", "particles", "unknowns", "springs", "method", "iteration", "objective", "gap",
                       "relative_error", "seconds", "setup_seconds", "factorizations", "reference_converged",
                       "reference_last_decrease"});
  cl::CsvTable crossover({"scene", "particles", "unknowns", "method", "target", "reached", "iterations",
                          "seconds", "seconds_without_setup", "factorizations", "setup_seconds"});
  std::printf("%s: one step of each scene to its minimum (after %d warm-up step(s) of PD with K = %d); caps: "
              "PD %d, Newton %d iterations\n",
              kLab, lab.warmup, options.iterations, lab.pd_cap, lab.newton_cap);
  std::printf("%-16s %8s %-7s %9s  %-22s %-22s %-22s %10s %8s  %s\n", "scene", "unknowns", "method", "setup/s",
              "1e-2: its, seconds", "1e-3: its, seconds", "1e-6: its, seconds", "factorized", "total/s", "note");
  for (const cl::Scene& scene : scenes) {
    cl::lab06::Solver pd(problem_of(scene), cl::lab06::Method::kProjectiveDynamics);
    cl::lab06::Solver newton(problem_of(scene), cl::lab06::Method::kNewton);
    cl::lab06::StepSettings settings;
    settings.gravity = scene.gravity;
    settings.iterations = options.iterations;
    cl::Particles start = scene.particles;
    for (int w = 0; w < lab.warmup; ++w) {
      const cl::lab06::StepReport report = pd.step(start, settings);
      if (!report.problem.empty()) {
        throw cl::InputError(scene.source + ": warm-up step " + std::to_string(w + 1) + " failed: " + report.problem);
      }
    }
    // Newton first, to round-off (or its cap): its end is the reference
    // minimum, and the PD run stops once within --stop-gap of it.
    const Curve newton_curve = measure_step(newton, start, settings, lab.newton_cap,
                                            std::numeric_limits<double>::quiet_NaN(), lab.stop_gap, lab.max_seconds);
    double best = std::numeric_limits<double>::infinity();
    for (const auto& record : newton_curve.records) best = std::min(best, record.objective);
    // How far the reference may still be from the minimum: Newton's last
    // decrease, relative (0 when it converged to round-off).
    const std::size_t count = newton_curve.records.size();
    const bool reference_converged =
        newton_curve.problem.empty() && newton_curve.failed_decreases == 0 && newton_curve.converged;
    const double reference_last_decrease =
        reference_converged || count < 2
            ? 0.0
            : (newton_curve.records[count - 2].objective - newton_curve.records[count - 1].objective) /
                  std::abs(newton_curve.records[count - 1].objective);
    const Curve pd_curve = measure_step(pd, start, settings, lab.pd_cap, best, lab.stop_gap, lab.max_seconds);
    for (const auto& record : pd_curve.records) best = std::min(best, record.objective);

    const auto unknowns = static_cast<long long>(pd.problem().map.unknowns());
    for (const Curve* curve : {&pd_curve, &newton_curve}) {
      std::vector<int> reached_at(std::size(kTargets), -1);
      for (std::size_t r = 0; r < curve->records.size(); ++r) {
        const auto& record = curve->records[r];
        const double gap = record.objective - best;
        const double relative = best != 0.0 ? gap / std::abs(best) : gap;
        curves.add_row({scene.name, static_cast<long long>(scene.particles.size()), unknowns,
                        static_cast<long long>(scene.springs.size()), curve->method,
                        static_cast<long long>(record.iteration), record.objective, gap, relative,
                        record.seconds + curve->setup_seconds, curve->setup_seconds,
                        static_cast<long long>(record.factorizations),
                        static_cast<long long>(reference_converged ? 1 : 0), reference_last_decrease});
        for (std::size_t t = 0; t < std::size(kTargets); ++t) {
          if (reached_at[t] < 0 && relative <= kTargets[t]) reached_at[t] = static_cast<int>(r);
        }
      }
      std::string cells[std::size(kTargets)];
      for (std::size_t t = 0; t < std::size(kTargets); ++t) {
        // A target near the reference's own uncertainty cannot be judged.
        const bool decidable = reference_converged || kTargets[t] > 10.0 * reference_last_decrease;
        const bool reached = decidable && reached_at[t] >= 0;
        const cl::lab06::IterationRecord none;
        const auto& record = reached ? curve->records[static_cast<std::size_t>(reached_at[t])] : none;
        crossover.add_row({scene.name, static_cast<long long>(scene.particles.size()), unknowns, curve->method,
                           kTargets[t], std::string(!decidable ? "undecided" : reached ? "yes" : "no"),
                           static_cast<long long>(record.iteration), record.seconds + curve->setup_seconds,
                           record.seconds, static_cast<long long>(record.factorizations), curve->setup_seconds});
        char cell[48];
        std::snprintf(cell, sizeof cell, "%6d %9.3g", record.iteration, record.seconds + curve->setup_seconds);
        cells[t] = reached ? cell : decidable ? "     -         -" : "     ?         ?";
      }
      const double total = curve->records.empty() ? 0.0 : curve->records.back().seconds + curve->setup_seconds;
      std::string note = curve->problem;
      if (curve->failed_decreases > 0) note += "a line search found no decrease";
      if (note.empty() && curve->timed_out) note = "stopped at --max-seconds";
      if (note.empty() && curve == &pd_curve && !curve->records.empty() &&
          curve->records.back().iteration == lab.pd_cap) {
        note = "stopped at the cap";
      }
      if (curve == &newton_curve && !reference_converged) {
        char text[96];
        std::snprintf(text, sizeof text, "%sreference: last decrease %.1e", note.empty() ? "" : "; ",
                      reference_last_decrease);
        note += text;
      }
      std::printf("%-16s %8lld %-7s %9.3g  %-22s %-22s %-22s %10d %8.3g  %s\n", scene.name.c_str(), unknowns,
                  curve->method.c_str(), curve->setup_seconds, cells[0].c_str(), cells[1].c_str(), cells[2].c_str(),
                  curve->records.empty() ? 0 : curve->records.back().factorizations, total, note.c_str());
    }
    std::fflush(stdout);
  }
  if (!options.out.empty()) {
    curves.write(cl::join_path(options.out, "convergence.csv"));
    crossover.write(cl::join_path(options.out, "crossover.csv"));
  }
  return 0;
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  if (lab.convergence) {
    cl::refuse_run_flags(options, "only for one run (not with --convergence)",
                         "--convergence writes CSV files, not a run summary");
    return run_convergence(options, lab);
  }
  if (!lab.sweep_scenes.empty()) throw cl::InputError("--sweep-scenes: only with --convergence");
  return run_steps(options, lab);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Lab 06: projective dynamics against Newton on the implicit-Euler objective. Runs a scene and "
               "writes per-step objective, iterations, time and strain and a summary; or (--convergence) one "
               "step of each method to its minimum and writes the convergence curves.",
               CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("pd-curtain-16", "pd", {"pd", "newton"});
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagMethod | cl::kFlagIterations | cl::kFlagDt | cl::kFlagSteps |
                             cl::kFlagOut | cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  app.add_option("--tolerance", lab.tolerance,
                 "stop a step's iterations once the objective's relative decrease falls below this (0: run all K)")
      ->check(cl::finite_number(true))
      ->capture_default_str();
  app.add_option("--stiffness", lab.stiffness, "replace every spring's stiffness (N/m)")
      ->check(cl::finite_number(false));
  app.add_flag("--convergence", lab.convergence,
               "one step of each method to the minimum: convergence.csv and crossover.csv");
  app.add_option("--warmup", lab.warmup, "--convergence: PD steps (K = --iterations) before the measured step")
      ->check(CLI::Range(0, 1'000'000))
      ->capture_default_str();
  app.add_option("--pd-cap", lab.pd_cap, "--convergence: the most PD iterations")
      ->check(CLI::Range(1, 100'000'000))
      ->capture_default_str();
  app.add_option("--newton-cap", lab.newton_cap, "--convergence: the most Newton iterations")
      ->check(CLI::Range(1, 1'000'000))
      ->capture_default_str();
  app.add_option("--stop-gap", lab.stop_gap,
                 "--convergence: end the PD run once its relative objective error (g - g*)/g*, g* Newton's "
                 "minimum, is this small")
      ->check(cl::finite_in(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--max-seconds", lab.max_seconds,
                 "--convergence: end a run after this many seconds of wall time (0: no limit)")
      ->check(cl::finite_number(true))
      ->capture_default_str();
  app.add_option("--sweep-scenes", lab.sweep_scenes, "--convergence: the scenes (default: --scene)")
      ->delimiter(',');
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
