// lab12_vertex_block_descent: the implicit-Euler step by vertex block descent
// (Chen et al. 2024), plain or with lab 11's Chebyshev acceleration.
//   default        run the scene's steps: per_step.csv, iterations.csv (every
//                  sweep of every step) and the run summary (colours, max_strain)
//   --convergence  one step from the scene's start, to the minimum:
//                  convergence.csv (objective_error = (g − g*)/g*, g* lab 06's
//                  Newton minimum, per sweep) and a table of the sweeps and
//                  seconds to each target
//   --stability    experiment 2: the table of k × Δt × K on the scene (stability.csv)
//   --live [PORT]  the scene's steps beside a page in the browser (run.cpp)

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/csv.h"
#include "common/driver.h"
#include "common/openmp.h"
#include "common/output.h"
#include "common/summary.h"
#include "descent.h"
#include "run.h"

namespace {

using cl::lab12::Method;
constexpr const char* kLab = CL_LAB_NAME;

using cl::lab12::LabOptions;
cl::LiveOptions live;  // --live [PORT]: the scene steps beside a page in the browser (./course live)

int run_steps(const cl::CommonOptions& options, LabOptions lab) {
  const Method method = cl::lab12::method_from_name(options.method);
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  cl::require_finite_springs(scene, "VBD minimises finite springs' energy");
  cl::start_run(options);
  cl::lab12::Solver solver(scene.particles.inv_mass, scene.springs, scene.dt);
  cl::lab12::Settings& settings = lab.settings;
  settings.gravity = scene.gravity;
  settings.iterations = options.iterations;
  settings.rho = cl::lab12::rho_for(solver, scene, method, lab);
  cl::CsvTable table({"step", "iteration", "objective", "omega", "restarted", "seconds"});
  const cl::lab12::RunIterationCallback on_iteration = [&](int step, const cl::lab12::IterationRecord& r) {
    table.add_row({static_cast<long long>(step), static_cast<long long>(r.iteration), r.objective, r.omega,
                   static_cast<long long>(r.restarted), r.seconds});
  };
  const cl::FrameOutput output =
      cl::frame_output(options, kLab, scene, "per_step.csv", cl::lab12::step_columns(), options.method);
  cl::Particles& particles = scene.particles;
  const cl::lab12::RunResult result = cl::lab12::run_steps(particles, solver, method, settings, scene.steps, nullptr,
                                                           options.out.empty() ? nullptr : on_iteration, output);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  std::printf("%s: scene %s, %s, init %s, K = %d, rho %.6f%s, %d colours, %d thread%s, %d steps of %.4g s\n", kLab,
              scene.name.c_str(), options.method.c_str(), lab.init.c_str(), options.iterations, settings.rho,
              method != Method::kVbdChebyshev ? " (not used)" : lab.estimate ? " (estimated)" : "",
              solver.colour_count(), lab.threads, lab.threads == 1 ? "" : "s", scene.steps, scene.dt);
  if (!result.problem.empty()) std::printf("  DIVERGED at step %d: %s\n", result.problem_step, result.problem.c_str());
  std::printf("  max strain %.3e, rms %.3e; %lld sweeps, %d restarts; %.3e s (%.3e s per step)\n", strain.max,
              strain.rms, result.iterations_done, result.restarts, result.seconds,
              result.steps_done ? result.seconds / result.steps_done : 0.0);
  cl::print_trajectory_note(options, "step");
  if (!options.out.empty()) table.write(cl::join_path(options.out, "iterations.csv"));
  if (!options.summary.empty()) {
    cl::RunSummary summary = cl::stepping_summary(kLab, options.method, scene, particles, strain, result.seconds);
    summary.iterations = options.iterations;
    summary.extra.update({{"init", lab.init}, {"colours", solver.colour_count()}, {"max_strain", strain.max},
                          {"threads", lab.threads}, {"rho", settings.rho},
                          {"rho_estimated", lab.estimate && method == Method::kVbdChebyshev},
                          {"tolerance", settings.tolerance}, {"restarts", result.restarts},
                          {"iterations_done", result.iterations_done}});
    cl::add_divergence(summary, result.problem, "diverged_at_step", result.problem_step);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

int run_convergence(const cl::CommonOptions& options, LabOptions lab) {
  cl::refuse_run_flags(options, "", "--convergence writes CSV files, not a run summary");
  const Method method = cl::lab12::method_from_name(options.method);
  const std::vector<cl::Scene> scenes = cl::load_scenes(options, lab.sweep_scenes, CL_LAB_SCENE_DIR);
  for (const cl::Scene& scene : scenes) cl::require_finite_springs(scene, "VBD minimises finite springs' energy");
  cl::start_run(options);
  cl::CsvTable table({"scene", "method", "init", "rho", "colours", "threads", "iteration", "objective",
                      "objective_error", "omega", "restarted", "seconds"});
  const std::vector<double> targets{1e-2, 1e-4, 1e-6};
  for (const cl::Scene& scene : scenes) {
    const cl::lab12::Solver solver(scene.particles.inv_mass, scene.springs, scene.dt);
    cl::lab12::Settings settings = lab.settings;
    settings.gravity = scene.gravity;
    settings.rho = cl::lab12::rho_for(solver, scene, method, lab);
    settings.iterations = options.iterations;
    // g*: lab 06's Newton to round-off, from the same prediction.
    cl::lab06::Solver newton(solver.problem(), cl::lab06::Method::kNewton);
    cl::lab06::StepSettings reference;
    reference.gravity = scene.gravity;
    reference.iterations = 50;
    reference.tolerance = 1e-15;
    cl::Particles copy = scene.particles;
    const double best = newton.step(copy, reference).objective;
    // The first step: the adaptive guess has no previous step, so it is y.
    const Eigen::Matrix3Xd y = cl::lab06::predict(scene.particles, scene.gravity, scene.dt);
    Eigen::Matrix3Xd x = y;
    std::vector<int> reached_at(targets.size(), -1);
    std::vector<double> seconds_at(targets.size(), 0.0);
    const cl::lab12::StepReport report = solver.minimise(x, y, method, settings, [&](const cl::lab12::IterationRecord& r) {
      const double error = (r.objective - best) / std::abs(best);
      table.add_row({scene.name, options.method, lab.init, settings.rho, static_cast<long long>(solver.colour_count()),
                     static_cast<long long>(lab.threads), static_cast<long long>(r.iteration), r.objective, error,
                     r.omega, static_cast<long long>(r.restarted), r.seconds});
      bool all = true;
      for (std::size_t t = 0; t < targets.size(); ++t) {
        if (reached_at[t] < 0 && error <= targets[t]) reached_at[t] = r.iteration, seconds_at[t] = r.seconds;
        all = all && reached_at[t] >= 0;
      }
      return all;
    });
    std::printf("%-16s %-14s rho %.6f, %d colours:", scene.name.c_str(), options.method.c_str(), settings.rho,
                solver.colour_count());
    for (std::size_t t = 0; t < targets.size(); ++t) {
      if (reached_at[t] >= 0) {
        std::printf("  error %g: %5d sweeps %9.3g s", targets[t], reached_at[t], seconds_at[t]);
      } else {
        std::printf("  error %g: not in %d", targets[t], report.iterations_done);
      }
    }
    std::printf("  restarts %d%s%s\n", report.restarts, report.problem.empty() ? "" : "; ", report.problem.c_str());
    std::fflush(stdout);
  }
  if (!options.out.empty()) table.write(cl::join_path(options.out, "convergence.csv"));
  return 0;
}

int run_stability(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::refuse_run_flags(options, "", "--stability writes stability.csv, not a run summary");
  const Method method = cl::lab12::method_from_name(options.method);
  if (method == Method::kVbdChebyshev && lab.estimate) throw cl::InputError("--stability: vbd-chebyshev needs --rho");
  const cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  cl::start_run(options);
  const std::vector<cl::lab12::StabilityCell> cells = cl::lab12::stability_cells(scene, method, lab.settings);
  std::printf("%s", cl::lab12::stability_markdown(cells).c_str());
  if (!options.out.empty()) cl::lab12::stability_csv(cells).write(cl::join_path(options.out, "stability.csv"));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 12: the implicit-Euler step by vertex block descent (Chen et al. 2024), plain or with Chebyshev "
      "acceleration. Runs a scene, or (--convergence) one step of it to the minimum.", CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("pd-curtain-16", "vbd", {"vbd", "vbd-chebyshev"});
  options.iterations = 10;
  cl::add_common_options(app, options, cl::kFlagScene | cl::kFlagMethod | cl::kFlagIterations | cl::kFlagDt |
                                           cl::kFlagSteps | cl::kFlagOut | cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  cl::add_live_option(app, live);
  double rho = -1.0;
  app.add_option("--init", lab.init, "the first iterate: inertia (y) or adaptive (Chen et al. 2024)")
      .one_of({"inertia", "adaptive"}).capture_default_str();
  app.add_option("--tolerance", lab.settings.tolerance,
                 "stop a step once the objective's relative decrease falls below this (0: run every sweep)")
      .non_negative().capture_default_str();
  app.add_option("--threads", lab.threads, "OpenMP threads for the sweep").range(1, 1024).capture_default_str();
  app.add_option("--rho", rho, "vbd-chebyshev: the spectral radius, in [0, 1) (default: estimated per scene)")
      .non_negative().only_for_methods({"vbd-chebyshev"});
  app.add_option("--estimate-iterations", lab.estimate_iterations, "plain sweeps that estimate rho (no --rho)")
      .range(2, 1'000'000).capture_default_str().only_for_methods({"vbd-chebyshev"});
  app.add_flag("--convergence", lab.convergence, "one step to the minimum: convergence.csv and the targets' table");
  app.add_flag("--stability", lab.stability, "experiment 2: every k, dt and K of the table on --scene (stability.csv)");
  app.add_option("--sweep-scenes", lab.sweep_scenes, "--convergence: the scenes (default: --scene)").delimiter(',');
  app.modes({{"--convergence", {"--sweep-scenes"}}, {"--stability", {"--steps"}}}, {"--steps", "--live"});
  return cl::run_main(app, argc, argv, [&] {
    if (rho >= 1.0) throw cl::InputError("--rho: " + cl::format_double(rho) + " is not in [0, 1)");
    if (rho >= 0.0) lab.settings.rho = rho, lab.estimate = false;
    if (!lab.convergence && !lab.sweep_scenes.empty()) throw cl::InputError("--sweep-scenes: only with --convergence");
    if (lab.convergence && lab.stability) throw cl::InputError("--stability: not with --convergence");
    if (lab.convergence || lab.stability) cl::refuse_run_flags(options, "only for a run of steps", "");
    lab.settings.init = cl::lab12::init_from_name(lab.init);
    cl::set_openmp_threads(lab.threads);
    if (live.on && (lab.convergence || lab.stability)) throw cl::InputError("--live: not with --convergence or --stability");
    if (live.on) return cl::lab12::run_live_scene(kLab, CL_LAB_SCENE_DIR, options, lab, live);
    if (lab.stability) return run_stability(options, lab);
    return lab.convergence ? run_convergence(options, lab) : run_steps(options, lab);
  });
}
