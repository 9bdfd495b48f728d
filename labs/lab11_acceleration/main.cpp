// lab11_acceleration: projective dynamics accelerated by Chebyshev (Wang 2015)
// and by L-BFGS on PD's matrix (Liu et al. 2017); Jacobi PBD by Chebyshev.
//   default        run the scene's steps: per_step.csv, iterations.csv (every
//                  iteration of every step) and the run summary
//   --convergence  one step from the scene's start, to the minimum:
//                  convergence.csv (objective_error = (g − g*)/g*, g* lab 06's
//                  Newton minimum; max_strain for PBD) and a table of the
//                  iterations and seconds to each target
//   --live [PORT]  the scene's steps beside a page in the browser (run.cpp)
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "common/cli.h"
#include "common/csv.h"
#include "common/driver.h"
#include "common/output.h"
#include "common/summary.h"
#include "run.h"

namespace {

using cl::lab11::Method;
constexpr const char* kLab = CL_LAB_NAME;

using cl::lab11::LabOptions;
cl::LiveOptions live;  // --live [PORT]: the scene steps beside a page in the browser (./course live)

int run_steps(const cl::CommonOptions& options, LabOptions lab) {
  const Method method = cl::lab11::method_from_name(options.method);
  cl::Scene scene = std::move(cl::lab11::load(options, {}, method, CL_LAB_SCENE_DIR).front());
  cl::start_run(options);
  cl::lab11::Solver solver(scene.particles.inv_mass, scene.springs, scene.dt);
  cl::lab11::Settings& settings = lab.settings;
  settings.gravity = scene.gravity;
  settings.iterations = options.iterations;
  settings.rho = cl::lab11::rho_for(solver, scene, method, lab);
  cl::CsvTable table({"step", "iteration", "objective", "max_strain", "omega", "restarted", "seconds"});
  const cl::lab11::RunIterationCallback on_iteration = [&](int step, const cl::lab11::IterationRecord& r) {
    table.add_row({static_cast<long long>(step), static_cast<long long>(r.iteration), r.objective, r.max_strain,
                   r.omega, static_cast<long long>(r.restarted), r.seconds});
  };
  const cl::FrameOutput output =
      cl::frame_output(options, kLab, scene, "per_step.csv", cl::lab11::step_columns(), options.method);
  cl::Particles& particles = scene.particles;
  const cl::lab11::RunResult result = cl::lab11::run_steps(particles, solver, method, settings, scene.steps, nullptr,
                                                           options.out.empty() ? nullptr : on_iteration, output);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  const bool chebyshev = method == Method::kPdChebyshev || method == Method::kJacobiChebyshev;
  std::printf("%s: scene %s, %s, K = %d, rho %.6f%s, gamma %g, delay %d, history %d, %d steps of %.4g s\n", kLab,
              scene.name.c_str(), options.method.c_str(), options.iterations, settings.rho,
              !chebyshev ? " (not used)" : lab.estimate ? " (estimated)" : "", settings.gamma, settings.delay,
              settings.history, scene.steps, scene.dt);
  if (!result.problem.empty()) std::printf("  DIVERGED at step %d: %s\n", result.problem_step, result.problem.c_str());
  std::printf("  max strain %.3e, rms %.3e; %lld iterations, %d restarts, %d failed line searches, %d descent "
              "fallbacks; %.3e s (%.3e s per step)\n", strain.max, strain.rms, result.iterations_done, result.restarts,
              result.failed_line_searches, result.descent_fallbacks, result.seconds,
              result.steps_done ? result.seconds / result.steps_done : 0.0);
  if (!options.out.empty()) table.write(cl::join_path(options.out, "iterations.csv"));
  cl::print_trajectory_note(options, "step");
  if (!options.summary.empty()) {
    cl::RunSummary summary = cl::stepping_summary(kLab, options.method, scene, particles, strain, result.seconds);
    summary.iterations = options.iterations;
    summary.extra.update(nlohmann::ordered_json{
        {"rho", settings.rho}, {"rho_estimated", lab.estimate}, {"gamma", settings.gamma}, {"delay", settings.delay},
        {"history", settings.history}, {"restarts", result.restarts}, {"iterations_done", result.iterations_done},
        {"failed_line_searches", result.failed_line_searches}, {"descent_fallbacks", result.descent_fallbacks}});
    cl::add_divergence(summary, result.problem, "diverged_at_step", result.problem_step);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

int run_convergence(const cl::CommonOptions& options, LabOptions lab) {
  cl::refuse_run_flags(options, "", "--convergence writes CSV files, not a run summary");
  const Method method = cl::lab11::method_from_name(options.method);
  const bool pd = cl::lab11::minimises_objective(method);
  // Every refusal before any output.
  const std::vector<cl::Scene> scenes = cl::lab11::load(options, lab.sweep_scenes, method, CL_LAB_SCENE_DIR);
  cl::start_run(options);
  cl::CsvTable table({"scene", "method", "rho", "history", "iteration", "objective", "objective_error", "max_strain",
                      "omega", "restarted", "seconds", "setup_seconds"});
  const std::vector<double> targets = pd ? std::vector<double>{1e-2, 1e-4, 1e-6} : std::vector<double>{lab.strain_target};
  for (const cl::Scene& scene : scenes) {
    cl::lab11::Solver solver(scene.particles.inv_mass, scene.springs, scene.dt);
    cl::lab11::Settings settings = lab.settings;
    settings.gravity = scene.gravity;
    settings.rho = cl::lab11::rho_for(solver, scene, method, lab);
    double best = 0.0;  // g*: lab 06's Newton to round-off
    if (pd) {
      cl::lab11::Settings newton = settings;
      newton.iterations = 50;
      newton.tolerance = 1e-15;
      cl::Particles reference = scene.particles;
      best = solver.step(reference, Method::kNewton, newton).objective;
    }
    settings.iterations = options.iterations;
    std::vector<int> reached_at(targets.size(), -1);
    std::vector<double> seconds_at(targets.size(), 0.0);
    const double setup = method == Method::kNewton ? 0.0 : solver.factor_seconds();
    cl::Particles particles = scene.particles;
    const cl::lab11::StepReport report = solver.step(particles, method, settings, [&](const cl::lab11::IterationRecord& r) {
      const double error = pd ? (r.objective - best) / std::abs(best) : r.max_strain;
      table.add_row({scene.name, options.method, settings.rho, static_cast<long long>(settings.history),
                     static_cast<long long>(r.iteration), r.objective, pd ? error : 0.0, r.max_strain, r.omega,
                     static_cast<long long>(r.restarted), r.seconds + setup, setup});
      bool all = true;
      for (std::size_t t = 0; t < targets.size(); ++t) {
        if (reached_at[t] < 0 && error <= targets[t]) reached_at[t] = r.iteration, seconds_at[t] = r.seconds + setup;
        all = all && reached_at[t] >= 0;
      }
      return all && pd;  // PBD runs its K sweeps, to show where the strain settles
    });
    std::printf("%-16s %-16s rho %.6f m %2d:", scene.name.c_str(), options.method.c_str(), settings.rho,
                settings.history);
    for (std::size_t t = 0; t < targets.size(); ++t) {
      if (reached_at[t] >= 0) {
        std::printf("  %s %g: %5d its %9.3g s", pd ? "error" : "strain", targets[t], reached_at[t], seconds_at[t]);
      } else {
        std::printf("  %s %g: not in %d", pd ? "error" : "strain", targets[t], report.iterations_done);
      }
    }
    std::printf("  restarts %d, descent fallbacks %d%s%s\n", report.restarts, report.descent_fallbacks,
                report.problem.empty() ? "" : "; ", report.problem.c_str());
    std::fflush(stdout);
  }
  if (!options.out.empty()) table.write(cl::join_path(options.out, "convergence.csv"));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 11: projective dynamics accelerated by Chebyshev and by L-BFGS on PD's matrix, and Jacobi PBD "
      "by Chebyshev. Runs a scene, or (--convergence) one step of it to the minimum.", CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults(
      "pd-curtain-16", "pd-chebyshev",
      {"pd", "pd-chebyshev", "pd-lbfgs", "newton", "jacobi", "jacobi-chebyshev", "gauss-seidel"});
  options.iterations = 10;
  cl::add_common_options(app, options, cl::kFlagScene | cl::kFlagMethod | cl::kFlagIterations | cl::kFlagDt |
                                           cl::kFlagSteps | cl::kFlagOut | cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  cl::add_live_option(app, live);
  double rho = -1.0;
  const std::vector<std::string> chebyshev{"pd-chebyshev", "jacobi-chebyshev"};
  app.add_option("--rho", rho, "the spectral radius for Chebyshev, in [0, 1) (default: estimated per scene)")
      .non_negative().only_for_methods(chebyshev);
  app.add_option("--gamma", lab.settings.gamma, "Chebyshev's under-relaxation, in (0, 2)")
      .positive().capture_default_str().only_for_methods(chebyshev);
  app.add_option("--delay", lab.settings.delay, "S: plain iterations before Chebyshev starts (>= 1)")
      .range(1, 1'000'000).capture_default_str().only_for_methods(chebyshev);
  app.add_option("--history", lab.settings.history, "m: L-BFGS pairs kept (>= 0)")
      .range(0, 1000).capture_default_str().only_for_methods({"pd-lbfgs"});
  app.add_option("--tolerance", lab.settings.tolerance,
                 "stop a step once the objective's relative decrease falls below this (0: run all K; PD methods)")
      .non_negative().capture_default_str().only_for_methods({"pd", "pd-chebyshev", "pd-lbfgs", "newton"});
  app.add_option("--estimate-iterations", lab.estimate_iterations, "plain iterations that estimate rho (no --rho)")
      .range(2, 1'000'000).capture_default_str().only_for_methods(chebyshev);
  app.add_flag("--convergence", lab.convergence, "one step to the minimum: convergence.csv and the targets' table");
  app.add_option("--sweep-scenes", lab.sweep_scenes, "--convergence: the scenes (default: --scene)").delimiter(',');
  app.add_option("--strain-target", lab.strain_target, "--convergence, PBD methods: the max strain to reach")
      .positive().capture_default_str().only_for_methods({"jacobi", "jacobi-chebyshev", "gauss-seidel"});
  app.modes({{"--convergence", {"--sweep-scenes", "--strain-target"}}}, {"--steps", "--live"});
  return cl::run_main(app, argc, argv, [&] {
    if (rho >= 1.0) throw cl::InputError("--rho: " + cl::format_double(rho) + " is not in [0, 1) (the iteration would not converge)");
    if (!(lab.settings.gamma < 2.0)) throw cl::InputError("--gamma: " + cl::format_double(lab.settings.gamma) + " is not in (0, 2)");
    if (rho >= 0.0) lab.settings.rho = rho, lab.estimate = false;
    if (!lab.convergence && !lab.sweep_scenes.empty()) throw cl::InputError("--sweep-scenes: only with --convergence");
    if (lab.convergence) cl::refuse_run_flags(options, "only for a run of steps (not with --convergence)", "");
    if (live.on && lab.convergence) throw cl::InputError("--live: not with --convergence (it runs one step)");
    if (live.on) return cl::lab11::run_live_scene(kLab, CL_LAB_SCENE_DIR, options, lab, live);
    return lab.convergence ? run_convergence(options, lab) : run_steps(options, lab);
  });
}
