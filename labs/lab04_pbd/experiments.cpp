#include "experiments.h"

#include <algorithm>
#include <cstdio>

#include "common/csv.h"
#include "common/driver.h"
#include "common/output.h"
#include "simulation.h"

namespace cl::lab04 {

namespace {

struct SweepRun {
  std::size_t scene = 0;
  int substeps = 1;
  int iterations = 0;
  RunResult result;
};

}  // namespace

PbdSettings frame_settings(const Scene& scene, const CommonOptions& options, const LabOptions& lab, int iterations) {
  PbdSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.iterations = iterations;
  settings.projection =
      options.method == "jacobi" ? Projection::kJacobi : Projection::kGaussSeidel;
  settings.omega = lab.omega;
  return settings;
}

int run_sweep(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, const LabOptions& lab,
              const std::vector<std::pair<int, int>>& points, const std::string& csv_name) {
  const std::vector<cl::Scene> scenes = cl::load_scenes(options, lab.sweep_scenes, scene_dir);
  cl::start_run(options);
  std::vector<ConstraintSet> constraints;
  for (const cl::Scene& scene : scenes) {
    constraints.push_back(make_constraint_set(scene.particles.size(), scene.springs));
  }

  std::vector<SweepRun> runs;
  std::vector<double> costs;
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    for (const auto& [substeps, iterations] : points) {
      runs.push_back({s, substeps, iterations, {}});
      costs.push_back(static_cast<double>(scenes[s].springs.size() + 1) * substeps * std::max(iterations, 1));
    }
  }
  cl::run_shared(cl::costliest_first(costs), [&](std::size_t r) {
    SweepRun& run = runs[r];
    const cl::Scene& scene = scenes[run.scene];
    cl::Particles particles = scene.particles;
    RunPlan plan;
    plan.frames = scene.steps;
    plan.window_frames = cl::frames_in(lab.window_seconds, scene.dt);
    plan.settle_tolerance = lab.settle_tolerance;
    plan.energy_frame = cl::frames_in(lab.energy_seconds, scene.dt);
    run.result = run_frames(particles, constraints[run.scene],
                                       frame_settings(scene, options, lab, run.iterations), run.substeps, plan);
  });

  cl::CsvTable table({"scene", "nx", "ny", "particles", "springs", "method", "dt", "substeps", "iterations",
                      "frames_run", "time_run", "window_seconds", "steady_max_strain", "steady_rms_strain",
                      "window_spread", "energy_start", "energy_seconds", "energy_at_seconds", "energy_end",
                      "max_energy_rise", "seconds", "status"});
  std::printf("%s: %s; each run until the mean max strain of three %.3g s windows agrees to %.3g (at most %s "
              "frames)\n",
              lab_name, options.method.c_str(), lab.window_seconds, lab.settle_tolerance,
              options.steps >= 0 ? std::to_string(options.steps).c_str() : "the scene's");
  std::printf("%-12s %8s %10s %12s %12s %8s %8s %13s %9s  %s\n", "scene", "substeps", "iterations", "steady_max",
              "steady_rms", "spread", "t_run/s", "E(te)-E(0)/J", "seconds", "status");
  for (const SweepRun& run : runs) {
    const cl::Scene& scene = scenes[run.scene];
    const RunResult& result = run.result;
    const std::string status = cl::settle_status(result.problem, result.problem_frame, result.settled);
    const bool ok = result.problem.empty();
    const bool measured = ok && result.windows_done > 0;
    const bool energy_known = ok && result.frames_done >= cl::frames_in(lab.energy_seconds, scene.dt);
    const double window_seconds = cl::frames_in(lab.window_seconds, scene.dt) * scene.dt;
    const double energy_seconds = cl::frames_in(lab.energy_seconds, scene.dt) * scene.dt;
    table.add_row({scene.name, static_cast<long long>(scene.grid_nx), static_cast<long long>(scene.grid_ny),
                   static_cast<long long>(scene.particles.size()), static_cast<long long>(scene.springs.size()),
                   options.method, scene.dt, static_cast<long long>(run.substeps),
                   static_cast<long long>(run.iterations), static_cast<long long>(result.frames_done),
                   result.frames_done * scene.dt, window_seconds, cl::cell_if(measured, result.window_max_strain),
                   cl::cell_if(measured, result.window_rms_strain),
                   cl::cell_if(measured && result.window_spread >= 0.0, result.window_spread), result.energy_start,
                   energy_seconds, cl::cell_if(energy_known, result.energy_at_mark), cl::cell_if(ok, result.energy_end),
                   result.max_energy_rise, result.seconds, status});
    if (measured) {
      std::printf("%-12s %8d %10d %12.4e %12.4e %8.1e %8.2f %13.4e %9.3f  %s\n", scene.name.c_str(), run.substeps,
                  run.iterations, result.window_max_strain, result.window_rms_strain, result.window_spread,
                  result.frames_done * scene.dt, energy_known ? result.energy_at_mark - result.energy_start : 0.0,
                  result.seconds, status.c_str());
    } else {
      std::printf("%-12s %8d %10d  %s\n", scene.name.c_str(), run.substeps, run.iterations,
                  ok ? "too short for one window" : status.c_str());
    }
  }
  if (!options.out.empty()) table.write(cl::join_path(options.out, csv_name));
  return 0;
}

}  // namespace cl::lab04
