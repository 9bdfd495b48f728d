#include "run.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "../lab06_projective_dynamics/experiments.h"
#include "../lab06_projective_dynamics/simulation.h"
#include "common/csv.h"
#include "common/driver.h"
#include "common/output.h"
#include "common/summary.h"

namespace cl::lab13 {

namespace {

// Constrained Newton converges every step while each finite spring's
// dt^2 k (1/m_i + 1/m_j) is at most kMaxStiffnessRatio (run.h); above it a
// run is refused here, before any step, instead of stalling and diverging.
void require_stiffness_in_range(const Scene& scene, const LabOptions& lab) {
  static_assert(kMaxStiffnessRatio == 1e8, "the message below says 1e8");
  const double dt2 = scene.dt * scene.dt;
  double top = std::numeric_limits<double>::infinity();  // the largest k in range, N/m
  int worst = -1;
  double worst_ratio = 0.0;
  for (std::size_t e = 0; e < scene.springs.size(); ++e) {
    const Spring& s = scene.springs[e];
    const double inverse_masses = scene.particles.inv_mass[s.i] + scene.particles.inv_mass[s.j];
    if (!std::isfinite(s.stiffness) || !(inverse_masses > 0.0)) continue;
    top = std::min(top, kMaxStiffnessRatio / (dt2 * inverse_masses));
    const double ratio = dt2 * s.stiffness * inverse_masses;
    if (ratio > worst_ratio) {
      worst_ratio = ratio;
      worst = static_cast<int>(e);
    }
  }
  if (worst < 0 || worst_ratio <= kMaxStiffnessRatio) return;
  const std::string what = lab.stiffness.empty() ? "springs[" + std::to_string(worst) + "].stiffness" : "--stiffness";
  char text[400];
  std::snprintf(text, sizeof text,
                "%s: %.3g N/m is above the range where constrained Newton converges on this scene at dt = %.3g s: "
                "finite k up to %.2g N/m (dt^2 k (1/m_i + 1/m_j) <= 1e8, kMaxStiffnessRatio; README.md, \"Where it "
                "holds\"), a smaller --dt for a stiffer k, or inf",
                what.c_str(), scene.springs[static_cast<std::size_t>(worst)].stiffness, scene.dt, top);
  throw InputError(text);
}

Scene load(const std::string& scene_dir, const CommonOptions& options, const LabOptions& lab) {
  Scene scene = load_scene_for(options, scene_dir);
  if (!lab.stiffness.empty()) set_stiffness(scene, parse_stiffness("--stiffness", lab.stiffness));
  if (options.method != "constrained-newton") {
    require_finite_springs(scene, "lab 06's " + options.method +
                                      " minimises finite springs' energy (use --method constrained-newton)");
  } else {
    require_stiffness_in_range(scene, lab);
  }
  return scene;
}

lab06::Method lab06_method(const std::string& name) {
  return name == "pd" ? lab06::Method::kProjectiveDynamics : lab06::Method::kNewton;
}

// --live: the scene steps beside a page. K, dt and k (finite springs only)
// are the knobs; a change of one, a pin or a held particle builds the solver
// again (a refactorization: the page says the step after it cost more).
int run_live_scene(const char* lab_name, const CommonOptions& options, const LabOptions& lab, Scene& scene,
                   const LiveOptions& live) {
  refuse_run_flags(options, "not with --live (the page shows every step)", "");
  const bool finite = !scene.springs.empty() && std::isfinite(scene.springs.front().stiffness);
  std::vector<Knob> declared{{"K", "iterations", 1, 100, 1.0 * options.iterations, true},
                             {"dt", "s", 1e-4, 0.05, scene.dt}};
  // k up to 1e8 N/m: the range where every step converges (README.md,
  // "Where it holds"; at 1e10 a 32² curtain's step stalls at the cap).
  if (finite) declared.push_back({"k", "N/m", 1, kLiveStiffnessMax, scene.springs.front().stiffness});
  LiveRun run{lab_name, options.method, Knobs(declared)};
  std::vector<Spring> springs = scene.springs;
  Settings settings = lab.settings;
  settings.gravity = scene.gravity;
  lab06::StepSettings lab06_settings;
  lab06_settings.gravity = scene.gravity;
  std::optional<Solver> solver;
  std::optional<lab06::Solver> lab06_solver;
  const bool constrained = options.method == "constrained-newton";
  // What the solver was built for: the masses (pins and held particles), Δt
  // and k. K alone changes none of it, so turning K keeps the solver, its
  // factor's analysis and a hard set's warm multipliers.
  BuiltFor built;
  run.changed = [&](const Knobs& knobs) -> std::string {
    const double k = finite ? knobs[2] : 0.0;
    if (!built.update(scene.particles.inv_mass, {knobs[1], k})) return "";
    if (finite) {
      for (Spring& spring : springs) spring.stiffness = k;
    }
    if (constrained) {
      solver.emplace(scene.particles.inv_mass, springs, knobs[1]);
    } else {
      lab06_solver.emplace(lab06::make_problem(scene.particles.inv_mass, springs, knobs[1]),
                           lab06_method(options.method));
    }
    return constrained ? "the solver (its matrix's pattern and analysis)" : "lab 06's solver";
  };
  run.step = [&](const Knobs& knobs) {
    if (!constrained) {
      lab06_settings.iterations = knobs.integer(0);
      const lab06::StepReport report = lab06_solver->step(scene.particles, lab06_settings);
      return StepVerdict{report.problem, true, report.seconds};
    }
    settings.iterations = knobs.integer(0);
    const StepReport report = solver->step(scene.particles, settings);
    return StepVerdict{report.problem, report.problem.empty(), report.seconds};
  };
  run.energy_name = "total energy";  // kinetic + potential + the finite springs' elastic
  run.energy = [&](const Particles& state) { return total_energy(state, springs, scene.gravity); };
  return run_live(scene, live, run, options.summary);
}

// Lab 06's Newton or PD on the same scene, for comparison.
int run_lab06(const char* lab_name, const CommonOptions& options, Scene& scene) {
  lab06::Solver solver(lab06::problem_of(scene), lab06_method(options.method));
  lab06::StepSettings settings;
  settings.gravity = scene.gravity;
  settings.iterations = options.iterations;
  const FrameOutput output = frame_output(options, lab_name, scene, "per_step.csv", lab06::step_columns(), options.method);
  const lab06::RunResult result = lab06::run_steps(scene.particles, solver, settings, scene.steps, nullptr, output);
  const StrainStats strain = strain_stats(scene.particles.x, scene.springs);
  std::printf("%s: scene %s, %s (lab 06), K = %d, %d steps of %.4g s\n", lab_name, scene.name.c_str(),
              options.method.c_str(), options.iterations, scene.steps, scene.dt);
  if (!result.problem.empty()) print_stopped("DIVERGED", "step", result.problem_step, scene.dt, result.problem);
  std::printf("  max strain %.3e; %lld iterations\n", strain.max, result.iterations_done);
  print_time(result.seconds, result.steps_done, "step");
  std::printf("\n");
  print_trajectory_note(options, "step");
  if (!options.summary.empty()) {
    RunSummary summary = stepping_summary(lab_name, options.method, scene, scene.particles, strain, result.seconds);
    summary.iterations = options.iterations;
    summary.extra["iterations_done"] = result.iterations_done;
    add_total_energy(summary, result.energy_end, result.energy_start);
    add_divergence(summary, result.problem, "diverged_at_step", result.problem_step);
    write_summary(options.summary, summary);
  }
  return 0;
}

}  // namespace

int run_scene(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, LabOptions lab,
              const LiveOptions& live) {
  Scene scene = load(scene_dir, options, lab);
  if (live.on) return run_live_scene(lab_name, options, lab, scene, live);
  start_run(options);
  if (options.method != "constrained-newton") return run_lab06(lab_name, options, scene);
  Solver solver(scene.particles.inv_mass, scene.springs, scene.dt);
  Settings& settings = lab.settings;
  settings.gravity = scene.gravity;
  settings.iterations = options.iterations;
  CsvTable table({"step", "iteration", "force_error", "constraint_error", "merit", "alpha", "backtracks", "seconds"});
  const RunIterationCallback on_iteration = [&](int step, const IterationRecord& r) {
    table.add_row({static_cast<long long>(step), static_cast<long long>(r.iteration), r.force_error,
                   r.constraint_error, r.merit, r.alpha, static_cast<long long>(r.backtracks), r.seconds});
  };
  std::vector<int> iterations;
  std::vector<double> force_errors, constraint_errors;
  std::vector<int> backtracks;
  const RunStepCallback on_step = [&](int, const StepReport& r) {
    iterations.push_back(r.iterations_done);
    force_errors.push_back(r.force_error);
    constraint_errors.push_back(r.constraint_error);
    backtracks.push_back(r.backtracks);
  };
  const FrameOutput output = frame_output(options, lab_name, scene, "per_step.csv", step_columns(), options.method);
  Particles& particles = scene.particles;
  const RunResult result = run_steps(particles, solver, settings, scene.steps,
                                     options.out.empty() ? nullptr : on_iteration, output, on_step);
  const StrainStats strain = strain_stats(particles.x, scene.springs);
  std::printf("%s: scene %s, %s (%s), start %s, warm %s, K = %d, tolerance %g, %d steps of %.4g s\n", lab_name,
              scene.name.c_str(), options.method.c_str(), solver.all_compliant() ? "schur" : "kkt",
              start_name(settings.start), warm_name(settings.warm), options.iterations, settings.tolerance,
              scene.steps, scene.dt);
  if (!result.problem.empty()) {
    print_stopped(result.step_failed ? "STOPPED" : "DIVERGED", "step", result.problem_step, scene.dt, result.problem);
  }
  std::printf("  max strain %.3e; %lld iterations (%.2f per step), %d backtracks, %d failed decreases, "
              "%d fallbacks (descent steps on g past a fold), %d refused factorizations, %d steps not converged\n",
              strain.max, result.iterations_done,
              result.steps_done ? static_cast<double>(result.iterations_done) / result.steps_done : 0.0,
              result.backtracks, result.failed_decreases, result.fallbacks, result.refused_factorizations,
              result.unconverged_steps);
  print_time(result.seconds, result.steps_done, "step", static_cast<double>(result.iterations_done), "iteration");
  std::printf("\n");
  print_trajectory_note(options, "step");
  if (!options.out.empty()) table.write(join_path(options.out, "iterations.csv"));
  if (!options.summary.empty()) {
    RunSummary summary = stepping_summary(lab_name, options.method, scene, particles, strain, result.seconds);
    summary.iterations = options.iterations;
    summary.extra["start"] = start_name(settings.start);
    summary.extra["warm"] = warm_name(settings.warm);
    summary.extra["tolerance"] = settings.tolerance;
    summary.extra["compression"] = settings.compression == lab09::Compression::kDrop ? "drop" : "keep";
    summary.extra["linear_solver"] = solver.all_compliant() ? "schur" : "kkt";
    summary.extra["iterations_done"] = result.iterations_done;
    summary.extra["backtracks"] = result.backtracks;
    summary.extra["failed_decreases"] = result.failed_decreases;
    summary.extra["fallbacks"] = result.fallbacks;
    summary.extra["exact_rescues"] = result.exact_rescues;
    summary.extra["refused_factorizations"] = result.refused_factorizations;
    summary.extra["unconverged_steps"] = result.unconverged_steps;
    summary.extra["iterations_per_step"] = iterations;
    summary.extra["force_error_per_step"] = force_errors;
    summary.extra["constraint_error_per_step"] = constraint_errors;
    summary.extra["backtracks_per_step"] = backtracks;
    add_total_energy(summary, result.energy_end, result.energy_start);
    add_divergence(summary, result.problem, "diverged_at_step", result.problem_step);
    write_summary(options.summary, summary);
  }
  return 0;
}

}  // namespace cl::lab13
