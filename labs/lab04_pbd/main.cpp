// lab04_pbd: position based dynamics on a scene, frame by frame: per-frame
// strain and energy (per_frame.csv), the trajectory (./course view) and OBJ
// meshes every --frames N frames, and the run summary. Two experiments (experiments.cpp),
// one invocation each:
//   --sweep-iterations 1,2,...,128          steady strain against K  -> strain_vs_iterations.csv
//   --sweep-substeps 1,2,...,64 --cost C    substeps × K = C fixed   -> substeps.csv
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/driver.h"
#include "common/live.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "experiments.h"
#include "pbd.h"
#include "simulation.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;
using cl::lab04::LabOptions;
cl::LiveOptions live;  // --live [PORT]: the scene steps beside a page in the browser (./course live)

// ------------------------------------------------------------------ one run

int run_one(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  cl::start_run(options);
  const std::string frames_dir = cl::join_path(options.out, "frames");
  if (options.frames > 0) cl::ensure_directory(frames_dir);

  const cl::lab04::ConstraintSet constraints = cl::lab04::make_constraint_set(scene.particles.size(), scene.springs);
  const cl::lab04::PbdSettings settings = cl::lab04::frame_settings(scene, options, lab, options.iterations);
  if (live.on) {
    cl::refuse_run_flags(options, "not with --live (the page shows every frame)", "");
    cl::LiveRun run{kLab, options.method, {{"K", "sweeps", 0, 200, 1.0 * options.iterations, true},
                                           {"dt", "s", 1e-4, 0.05, scene.dt},
                                           {"substeps", "", 1, 64, 1.0 * lab.substeps, true}}};
    run.step = [&](const cl::Knobs& knobs) {
      cl::lab04::PbdSettings frame = settings;
      frame.iterations = knobs.integer(0);
      frame.dt = knobs[1];
      cl::lab04::advance_frame(scene.particles, constraints, frame, knobs.integer(2));
      return cl::StepVerdict{};
    };
    return cl::run_live(scene, live, run, options.summary);
  }
  cl::lab04::RunPlan plan;
  plan.frames = scene.steps;
  plan.window_frames = cl::frames_in(lab.window_seconds, scene.dt);
  const double window_seconds = plan.window_frames * scene.dt;

  cl::FrameOutput output =
      cl::frame_output(options, kLab, scene, "per_frame.csv", cl::lab04::frame_columns(), options.method);
  output.obj_every = options.frames;
  output.obj_dir = frames_dir;

  cl::Particles& particles = scene.particles;
  const cl::lab04::RunResult result =
      cl::lab04::run_frames(particles, constraints, settings, lab.substeps, plan, nullptr, output);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  const double kinetic = cl::kinetic_energy(particles);
  const double potential = cl::potential_energy(particles, scene.gravity);
  const bool diverged = !result.problem.empty();

  std::printf("%s: scene %s, %s, K = %d, %d substep(s) of %.4g s per %.4g s frame, %d frames\n", kLab,
              cl::describe(scene).c_str(), options.method.c_str(), options.iterations, lab.substeps,
              scene.dt / lab.substeps, scene.dt, scene.steps);
  if (diverged) {
    cl::print_stopped("DIVERGED", "frame", result.problem_frame, scene.dt, result.problem);
  } else {
    std::printf("  final:   max strain %.3e  rms %.3e\n", strain.max, strain.rms);
    if (result.windows_done > 0) {
      std::printf("  last %.3g s: mean max strain %.3e  mean rms %.3e", window_seconds, result.window_max_strain,
                  result.window_rms_strain);
      if (result.previous_window_max_strain >= 0.0) {
        std::printf("  (the %.3g s before: %.3e)", window_seconds, result.previous_window_max_strain);
      }
      std::printf("\n");
    }
    cl::print_energies("energy:  ", kinetic, potential, std::nullopt, result.energy_start);
  }
  const double projections = static_cast<double>(result.frames_done) * lab.substeps * options.iterations *
                             static_cast<double>(scene.springs.size());
  cl::print_time(result.seconds, result.frames_done, "frame", projections, "spring projection");
  std::printf("\n");
  if (result.obj_frames > 0) std::printf("  %d OBJ frames in %s\n", result.obj_frames, frames_dir.c_str());
  cl::print_trajectory_note(options);

  if (!options.summary.empty()) {
    cl::RunSummary summary = cl::stepping_summary(kLab, options.method, scene, particles, strain, result.seconds);
    summary.iterations = options.iterations;
    summary.extra["substeps"] = lab.substeps;
    if (settings.projection == cl::lab04::Projection::kJacobi) summary.extra["omega"] = lab.omega;
    summary.extra["rms_strain_error"] = strain.rms;
    if (!diverged && result.windows_done > 0) {
      summary.extra["window_seconds"] = window_seconds;
      summary.extra["window_max_strain_error"] = result.window_max_strain;
      summary.extra["window_rms_strain_error"] = result.window_rms_strain;
    }
    cl::add_energies(summary, kinetic, potential, std::nullopt, result.energy_start);
    cl::add_divergence(summary, result.problem, "diverged_at_frame", result.problem_frame);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  if (options.frames > 0 && options.out.empty()) {
    throw cl::InputError("--frames: needs --out DIR for the trajectory and the OBJ files");
  }
  const bool sweep = !lab.sweep_iterations.empty() || !lab.sweep_substeps.empty();
  if (!sweep) {
    if (!lab.sweep_scenes.empty()) {
      throw cl::InputError("--sweep-scenes: only with --sweep-iterations or --sweep-substeps");
    }
    return run_one(options, lab);
  }
  cl::refuse_run_flags(options, "not with a sweep (run one configuration instead)",
                       "a sweep writes a CSV, not a run summary");
  std::vector<std::pair<int, int>> points;  // (substeps, iterations)
  if (!lab.sweep_iterations.empty()) {
    for (const int k : lab.sweep_iterations) points.emplace_back(lab.substeps, k);
    return cl::lab04::run_sweep(kLab, CL_LAB_SCENE_DIR, options, lab, points, "strain_vs_iterations.csv");
  }
  if (lab.cost < 1) throw cl::InputError("--sweep-substeps: needs --cost C (substeps × iterations)");
  for (const int n : lab.sweep_substeps) {
    if (lab.cost % n != 0) {
      throw cl::InputError("--sweep-substeps: " + std::to_string(n) + " does not divide --cost " +
                           std::to_string(lab.cost));
    }
    points.emplace_back(n, lab.cost / n);
  }
  return cl::lab04::run_sweep(kLab, CL_LAB_SCENE_DIR, options, lab, points, "substeps.csv");
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 04: position based dynamics. Runs a scene and writes per-frame strain and energy, OBJ "
      "frames and a summary; or sweeps iterations or substeps and writes the steady strain.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("curtain-16", "gauss-seidel", {"gauss-seidel", "jacobi"});
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagMethod | cl::kFlagIterations | cl::kFlagDt | cl::kFlagSteps |
                             cl::kFlagOut | cl::kFlagSummary | cl::kFlagFrames);
  app.get_option("--frames")
      .description("keep every N-th frame in OUT/trajectory.json and .bin (./course view OUT) and write its OBJ "
                   "mesh into OUT/frames/");
  LabOptions lab;
  cl::add_live_option(app, live);
  app.add_option("--substeps", lab.substeps, "PBD steps of dt/n per frame")
      .range(1, 1'000'000)
      .capture_default_str();
  app.add_option("--omega", lab.omega, "Jacobi relaxation factor ω, as in lab 03 (0 leaves x unchanged; >= 2 diverges)")
      .non_negative()
      .capture_default_str()
      .only_for_methods({"jacobi"});
  app.add_option("--window", lab.window_seconds, "averaging window in seconds for the steady strain")
      .finite_in(1e-9, 1e9)
      .capture_default_str();
  cl::Option iterations_sweep =
      app.add_option("--sweep-iterations", lab.sweep_iterations,
                     "run the scene(s) once per K in this list (e.g. 1,2,4,8) and write strain_vs_iterations.csv; "
                     "--steps is then the most frames a run may take to settle")
          .delimiter(',')
          .range(0, 1'000'000);
  cl::Option substeps_sweep =
      app.add_option("--sweep-substeps", lab.sweep_substeps,
                     "run the scene(s) once per substep count n in this list with K = C/n (--cost C) and write "
                     "substeps.csv")
          .delimiter(',')
          .range(1, 1'000'000);
  iterations_sweep.excludes(substeps_sweep);
  app.add_option("--cost", lab.cost, "substeps × iterations, fixed across --sweep-substeps")
      .range(1, 100'000'000);
  app.add_option("--sweep-scenes", lab.sweep_scenes,
                 "scenes for a sweep (default: --scene), e.g. curtain-8,curtain-16")
      .delimiter(',');
  app.add_option("--settle-tolerance", lab.settle_tolerance,
                 "sweeps: a run has settled when the mean max strain of its last three windows agree to this "
                 "relative spread (0: run all --steps frames)")
      .finite_in(0.0, 1e9)
      .capture_default_str();
  app.add_option("--energy-seconds", lab.energy_seconds, "sweeps: compare the total energy at this time")
      .finite_in(0.0, 1e9)
      .capture_default_str();
  app.modes({{"--sweep-iterations", {"--sweep-scenes", "--settle-tolerance", "--energy-seconds"}},
             {"--sweep-substeps", {"--sweep-scenes", "--settle-tolerance", "--energy-seconds", "--cost"}}}, {});
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
