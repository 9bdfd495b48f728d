#include "experiments.h"

#include <cmath>
#include <cstdio>
#include <optional>

#include "common/csv.h"
#include "common/driver.h"
#include "common/output.h"

namespace cl::lab08 {

FrameSettings frame_settings(const Scene& scene, const CommonOptions& options, const LabOptions& lab, int iterations) {
  FrameSettings settings;
  settings.method = options.method == "pbd" ? Method::kPbd : Method::kXpbd;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.iterations = iterations;
  settings.substeps = lab.substeps;
  return settings;
}

int run_sweep(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, const LabOptions& lab) {
  const cl::Scene scene = cl::load_scene_for(options, scene_dir);
  cl::start_run(options);
  const cl::lab04::ConstraintSet constraints = cl::lab04::make_constraint_set(scene.particles.size(), scene.springs);
  const std::optional<double> hanging = hanging_chain_stretch(scene.particles, scene.springs, scene.gravity);

  const std::vector<int>& ks = lab.sweep_iterations;
  std::vector<RunResult> results(ks.size());
  cl::run_shared(cl::costliest_first(std::vector<double>(ks.begin(), ks.end())), [&](std::size_t r) {
    cl::Particles particles = scene.particles;
    RunPlan plan;
    plan.frames = scene.steps;
    plan.window_frames = cl::frames_in(lab.window_seconds, scene.dt);
    plan.settle_tolerance = lab.settle_tolerance;
    results[r] = run_frames(particles, constraints, frame_settings(scene, options, lab, ks[r]), plan);
  });

  cl::CsvTable table({"scene", "method", "dt", "substeps", "iterations", "frames_run", "time_run", "window_seconds",
                      "steady_total_stretch", "material_total_stretch", "stiffness_ratio", "steady_max_strain",
                      "window_spread", "max_energy_rise", "seconds", "status"});
  std::printf("%s: %s on %s; each run until the mean total stretch of three %.3g s windows agrees to %.3g "
              "(at most %d frames)\n",
              lab_name, options.method.c_str(), cl::describe(scene).c_str(), lab.window_seconds, lab.settle_tolerance,
              scene.steps);
  if (hanging) std::printf("  hanging at rest with its springs' stiffness: total stretch %.6e m\n", *hanging);
  std::printf("%10s %14s %12s %10s %8s %8s  %s\n", "iterations", "steady_stretch", "k_eff/k", "max_strain",
              "spread", "t_run/s", "status");
  for (std::size_t r = 0; r < ks.size(); ++r) {
    const RunResult& result = results[r];
    const std::string status = cl::settle_status(result.problem, result.problem_frame, result.settled);
    const bool measured = result.problem.empty() && result.windows_done > 0;
    // k_eff / k: the stiffness the chain shows, relative to its material's
    // (the hanging stretch is proportional to 1/k).
    const bool ratio_known = measured && hanging && result.window_total_stretch > 0.0;
    const double ratio = ratio_known ? *hanging / result.window_total_stretch : 0.0;
    table.add_row({scene.name, options.method, scene.dt, static_cast<long long>(lab.substeps),
                   static_cast<long long>(ks[r]), static_cast<long long>(result.frames_done),
                   result.frames_done * scene.dt, cl::frames_in(lab.window_seconds, scene.dt) * scene.dt,
                   cl::cell_if(measured, result.window_total_stretch),
                   cl::cell_if(hanging.has_value(), hanging.value_or(0.0)), cl::cell_if(ratio_known, ratio),
                   cl::cell_if(measured, result.window_max_strain),
                   cl::cell_if(measured && result.window_spread >= 0.0, result.window_spread), result.max_energy_rise,
                   result.seconds, status});
    if (measured) {
      std::printf("%10d %14.6e %12.4g %10.3e %8.1e %8.2f  %s\n", ks[r], result.window_total_stretch,
                  ratio_known ? ratio : std::nan(""), result.window_max_strain, result.window_spread,
                  result.frames_done * scene.dt, status.c_str());
    } else {
      std::printf("%10d  %s\n", ks[r], result.problem.empty() ? "too short for one window" : status.c_str());
    }
  }
  if (!options.out.empty()) {
    table.write(cl::join_path(options.out, "stretch_vs_iterations_" + options.method + ".csv"));
  }
  return 0;
}

}  // namespace cl::lab08
