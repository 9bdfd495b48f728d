// lab05_strain_limiting: a mass-spring cloth stepped explicitly, with a strain
// limiter after every step: per-step strain and energy (per_step.csv) and the
// run summary. Two experiments (experiments.cpp), one invocation each:
//   --compare-limits none,springs,...   the scene once per limiter -> strain_vs_time.csv,
//                                        compare_limits.csv, shapes.csv
//   --stability-map                      stiffness × Δt, each cell unlimited and
//                                        limited                   -> stability_map.csv
#include <cstdio>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/driver.h"
#include "common/live.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "experiments.h"
#include "simulation.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;
using cl::lab05::LabOptions;
cl::LiveOptions live;  // --live [PORT]: the scene steps beside a page in the browser (./course live)
using cl::lab05::Limit;

// ------------------------------------------------------------------ one run

int run_one(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  const Limit limit = cl::lab05::limit_from(lab.limit);
  const cl::lab05::LimitedSystem system = cl::lab05::make_limited_system(scene, limit);
  cl::start_run(options);
  const cl::lab05::StepSettings settings = cl::lab05::step_settings(scene, options, lab, limit);

  if (live.on) {  // the band's upper end; with a limiter, a rise of energy past the scale is reported, not stopped at
    cl::refuse_run_flags(options, "not with --live (the page shows every step)", "");
    cl::LiveRun run{kLab, "limit " + lab.limit, {{"K", "sweeps", 0, 200, 1.0 * options.iterations, true},
                                                 {"dt", "s", 1e-5, 0.05, scene.dt},
                                                 {"sigma_max", "", 1, 2, lab.sigma_max}}};
    run.step = [&](const cl::Knobs& knobs) {
      cl::lab05::StepSettings step = settings;
      step.iterations = knobs.integer(0);
      step.dt = knobs[1];
      step.sigma_max = knobs[2];
      cl::lab05::limited_step(scene.particles, system, step);
      return cl::StepVerdict{};
    };
    run.energy_stops = cl::lab05::checks_energy(limit);
    return cl::run_live(scene, live, run, options.summary);
  }
  cl::FrameOutput output =
      cl::frame_output(options, kLab, scene, "per_step.csv", cl::lab05::step_columns(), "limit " + lab.limit);
  cl::Particles& particles = scene.particles;
  const cl::lab05::RunResult result =
      cl::lab05::run_steps(particles, system, settings, scene.steps, cl::lab05::checks_energy(limit), nullptr, output);
  const bool diverged = !result.problem.empty();
  const cl::lab05::SignedStrain strain = cl::lab05::signed_strain(particles.x, system.springs);
  const cl::StrainStats error = cl::strain_stats(particles.x, system.springs);
  const double kinetic = cl::kinetic_energy(particles);
  const double potential = cl::potential_energy(particles, scene.gravity);
  const double elastic = cl::lab05::elastic_energy(particles.x, system.springs);

  std::printf("%s: scene %s, limit %s, band [%.4g, %.4g], K = %d, dt = %.4g s, %d steps\n", kLab,
              cl::describe(scene).c_str(), cl::lab05::limit_name(limit), lab.sigma_min, lab.sigma_max,
              options.iterations, scene.dt, scene.steps);
  if (diverged) {
    cl::print_stopped("UNSTABLE", "step", result.problem_step, scene.dt, result.problem);
  } else {
    std::printf("  final:      strain (l/L - 1) from %+.4e to %+.4e\n", strain.min, strain.max);
    std::printf("  whole run:  strain from %+.4e to %+.4e\n", result.min_strain, result.max_strain);
    cl::print_energies("energy:     ", kinetic, potential, elastic, result.energy_start);
  }
  const std::string outside = cl::lab05::band_problem(result, limit, lab, options.iterations);
  if (!outside.empty()) std::printf("  WARNING: %s\n", outside.c_str());
  cl::print_trajectory_note(options, "step");
  cl::print_time(result.seconds, result.steps_done, "step");
  std::printf("\n");
  // A limited run whose energy rose past the scene's scale and did not stop:
  // the limiter held it only if the band held and the rise stayed within what
  // the scene can release inside the band (README.md, "Bounded only by the
  // limiter"); otherwise nothing held it, and the run says so.
  const bool exceeded = limit != Limit::kNone && result.energy_exceeded_step >= 0 && !diverged;
  const bool contained = exceeded && cl::lab05::energy_contained(result, outside.empty());
  if (contained) {
    std::fprintf(stderr, "%s: bounded only by the limiter: from step %d (t = %.4g s) the total energy rose up to "
                 "%.3g J above its start, more than the scene's %.3g J but within the %.3g J it can release inside "
                 "the band; the run went on, held by the limiter alone (summary: energy_contained_by_limiter)\n",
                 kLab, result.energy_exceeded_step, result.energy_exceeded_step * scene.dt, result.max_energy_rise,
                 result.energy_scale, result.energy_bound);
  } else if (exceeded) {
    char why[120] = "and the band was lost";
    if (outside.empty()) {
      std::snprintf(why, sizeof why, "beyond the %.3g J it can release inside the band", result.energy_bound);
    }
    std::fprintf(stderr, "%s: energy not contained: from step %d (t = %.4g s) the total energy rose up to %.3g J "
                 "above its start, more than the scene's %.3g J, %s; the run went on, but nothing held it "
                 "(summary: energy_contained_by_limiter false)\n",
                 kLab, result.energy_exceeded_step, result.energy_exceeded_step * scene.dt, result.max_energy_rise,
                 result.energy_scale, why);
  }
  if (!options.summary.empty()) {
    cl::RunSummary summary =
        cl::stepping_summary(kLab, cl::lab05::limit_name(limit), scene, particles, error, result.seconds);
    summary.iterations = options.iterations;
    summary.extra["limit"] = cl::lab05::limit_name(limit);
    summary.extra["sigma_min"] = lab.sigma_min;
    summary.extra["sigma_max"] = lab.sigma_max;
    summary.extra["max_strain"] = strain.max;
    summary.extra["min_strain"] = strain.min;
    summary.extra["max_strain_over_run"] = result.max_strain;
    summary.extra["min_strain_over_run"] = result.min_strain;
    summary.extra["rms_strain_error"] = error.rms;
    summary.extra["seconds_per_step"] = cl::lab05::per_step(result);
    cl::add_energies(summary, kinetic, potential, elastic, result.energy_start);
    if (limit == Limit::kSprings) summary.extra["band_held"] = outside.empty() && !diverged;
    if (limit != Limit::kNone) summary.extra["energy_contained_by_limiter"] = contained;
    if (contained) summary.extra["energy_contained_from_step"] = result.energy_exceeded_step;
    if (exceeded) summary.extra["energy_exceeded_from_step"] = result.energy_exceeded_step;
    if (limit != Limit::kNone) {
      summary.extra["max_energy_rise"] = result.max_energy_rise;
      summary.extra["energy_bound"] = result.energy_bound;
    }
    cl::add_divergence(summary, result.problem, "diverged_at_step", result.problem_step);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  if (lab.sigma_min > lab.sigma_max) {
    char text[160];
    std::snprintf(text, sizeof text, "--sigma-min %.10g is above --sigma-max %.10g (the band must not be empty)",
                  lab.sigma_min, lab.sigma_max);
    throw cl::InputError(text);
  }
  if (lab.stability_map && !lab.compare_limits.empty()) {
    throw cl::InputError("--stability-map: not with --compare-limits (one experiment per run)");
  }
  if (lab.stability_map || !lab.compare_limits.empty()) {
    cl::refuse_run_flags(options, "only for one run (not with --stability-map or --compare-limits)", "");
  }
  if (lab.stability_map) return cl::lab05::stability_map(kLab, CL_LAB_SCENE_DIR, options, lab);
  if (!lab.compare_limits.empty()) {
    cl::refuse_run_flags(options, "", "--compare-limits writes CSVs, not a run summary");
    return cl::lab05::compare_limits(kLab, CL_LAB_SCENE_DIR, options, lab);
  }
  return run_one(options, lab);
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 05: strain limiting. Steps a mass-spring scene explicitly and limits the strain of its springs "
      "or triangles to [sigma-min, sigma-max] after every step; writes per-step strain and energy and a "
      "summary. Or compares the limiters, or maps stability over stiffness and dt.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("soft-curtain-32");
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagIterations | cl::kFlagDt | cl::kFlagSteps | cl::kFlagOut |
                             cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  cl::add_live_option(app, live);
  app.add_option("--limit", lab.limit, "the limiter run after each step")
      .one_of({"none", "springs", "triangles-area", "triangles-stretch"})
      .capture_default_str();
  app.add_option("--sigma-min", lab.sigma_min, "lower bound of the band for l/L (> 0)")
      .positive()
      .capture_default_str();
  app.add_option("--sigma-max", lab.sigma_max, "upper bound of the band for l/L (>= sigma-min)")
      .positive()
      .capture_default_str();
  app.add_option("--compare-limits", lab.compare_limits,
                 "run the scene once per limiter in this list (e.g. none,springs,triangles-area,triangles-stretch) "
                 "and write strain_vs_time.csv, compare_limits.csv and shapes.csv")
      .delimiter(',')
      .one_of({"none", "springs", "triangles-area", "triangles-stretch"});
  app.add_flag("--stability-map", lab.stability_map,
               "run the scene at every (--map-stiffness, --map-dt) pair, without a limiter and, where that blows "
               "up, with --limit; write stability_map.csv");
  app.add_option("--map-stiffness", lab.map_stiffness, "spring stiffnesses (N/m) for --stability-map")
      .delimiter(',')
      .positive()
      .capture_default_str();
  app.add_option("--map-dt", lab.map_dt, "time steps (s) for --stability-map")
      .delimiter(',')
      .positive()
      .capture_default_str();
  app.add_option("--map-seconds", lab.map_seconds, "simulated time per --stability-map run (s)")
      .finite_in(1e-9, 1e6)
      .capture_default_str();
  app.modes({{"--stability-map", {"--map-stiffness", "--map-dt", "--map-seconds"}}, {"--compare-limits", {}}}, {});
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
