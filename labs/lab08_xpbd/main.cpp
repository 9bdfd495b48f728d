// lab08_xpbd: PBD or XPBD on a scene, frame by frame: per-frame strain,
// stretch and energy (per_frame.csv) and the run summary with each spring's
// multiplier. The experiment (experiments.cpp), one invocation per method:
//   --sweep-iterations 1,2,...,1024   steady stretch against K -> stretch_vs_iterations_<method>.csv
#include <algorithm>
#include <cmath>
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
#include "xpbd.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;
using cl::lab08::LabOptions;
cl::LiveOptions live;  // --live [PORT]: the scene steps beside a page in the browser (./course live)

// The multipliers in newtons: λ / Δt² with Δt the substep (λ is force × Δt²).
std::vector<double> multipliers_in_newtons(const Eigen::VectorXd& lambda, double substep) {
  std::vector<double> forces(static_cast<std::size_t>(lambda.size()));
  for (Eigen::Index s = 0; s < lambda.size(); ++s) forces[static_cast<std::size_t>(s)] = lambda[s] / (substep * substep);
  return forces;
}

// ------------------------------------------------------------------ one run

int run_one(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  cl::start_run(options);

  const cl::lab04::ConstraintSet constraints = cl::lab04::make_constraint_set(scene.particles.size(), scene.springs);
  const cl::lab08::FrameSettings settings = cl::lab08::frame_settings(scene, options, lab, options.iterations);
  const std::optional<double> hanging = cl::lab08::hanging_chain_stretch(scene.particles, scene.springs, scene.gravity);
  if (live.on) {  // k sets every spring's stiffness (XPBD's compliance 1/k; PBD's springs stay hard)
    cl::refuse_run_flags(options, "not with --live (the page shows every frame)", "");
    const bool finite = !scene.springs.empty() && std::isfinite(scene.springs[0].stiffness);
    const double k0 = finite ? scene.springs[0].stiffness : 1e4;
    cl::LiveRun run{kLab, options.method, {{"K", "sweeps", 0, 200, 1.0 * options.iterations, true},
                                           {"dt", "s", 1e-4, 0.05, scene.dt}, {"k", "N/m", 1, 1e8, k0}}};
    cl::lab04::ConstraintSet springs = constraints;
    Eigen::VectorXd lambda;
    run.changed = [&](const cl::Knobs& knobs) -> std::string {  // XPBD keeps no matrix: nothing is rebuilt
      for (cl::Spring& spring : springs.springs) spring.stiffness = knobs[2] != k0 ? knobs[2] : spring.stiffness;
      return "";
    };
    run.step = [&](const cl::Knobs& knobs) {
      cl::lab08::FrameSettings frame = settings;
      frame.iterations = knobs.integer(0);
      frame.dt = knobs[1];
      cl::lab08::advance_frame(scene.particles, springs, frame, lambda);
      return cl::StepVerdict{};
    };
    run.energy_name = "total energy";  // kinetic + potential + the springs' elastic
    run.energy = [&](const cl::Particles& state) {
      return cl::kinetic_energy(state) + cl::potential_energy(state, scene.gravity) +
             (settings.method == cl::lab08::Method::kXpbd ? cl::lab08::elastic_energy(state.x, springs.springs) : 0.0);
    };
    return cl::run_live(scene, live, run, options.summary);
  }
  cl::lab08::RunPlan plan;
  plan.frames = scene.steps;
  plan.window_frames = cl::frames_in(lab.window_seconds, scene.dt);
  const double window_seconds = plan.window_frames * scene.dt;

  cl::FrameOutput output =
      cl::frame_output(options, kLab, scene, "per_frame.csv", cl::lab08::frame_columns(), options.method);

  cl::Particles& particles = scene.particles;
  const cl::lab08::RunResult result = cl::lab08::run_frames(particles, constraints, settings, plan, nullptr, output);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  const double stretch = cl::lab08::total_stretch(particles.x, scene.springs);
  const double kinetic = cl::kinetic_energy(particles);
  const double potential = cl::potential_energy(particles, scene.gravity);
  // PBD's springs are hard constraints: they store nothing (as in run_frames).
  const double elastic =
      settings.method == cl::lab08::Method::kXpbd ? cl::lab08::elastic_energy(particles.x, scene.springs) : 0.0;
  const bool diverged = !result.problem.empty();
  const double substep = scene.dt / lab.substeps;
  const std::vector<double> forces = multipliers_in_newtons(result.lambda, substep);

  std::printf("%s: scene %s, %s, K = %d, %d substep(s) of %.4g s per %.4g s frame, %d frames\n", kLab,
              cl::describe(scene).c_str(), options.method.c_str(), options.iterations, lab.substeps, substep, scene.dt,
              scene.steps);
  if (diverged) {
    cl::print_stopped("DIVERGED", "frame", result.problem_frame, scene.dt, result.problem);
  } else {
    std::printf("  final:   max strain %.3e  rms %.3e  total stretch %.6e m", strain.max, strain.rms, stretch);
    if (hanging) std::printf("  (hanging at rest from its pin, springs at their k: %.6e m)", *hanging);
    std::printf("\n");
    if (result.windows_done > 0) {
      std::printf("  last %.3g s: mean total stretch %.6e m  mean max strain %.3e\n", window_seconds,
                  result.window_total_stretch, result.window_max_strain);
    }
    if (!forces.empty()) {
      const auto [low, high] = std::minmax_element(forces.begin(), forces.end());
      std::printf("  multipliers λ/Δt² (last substep): %.6g N … %.6g N (spring 0: %.6g N; < 0 is tension)\n",
                  *low, *high, forces.front());
    }
    cl::print_energies("energy:  ", kinetic, potential, elastic, result.energy_start);
  }
  const double projections = static_cast<double>(result.frames_done) * lab.substeps * options.iterations *
                             static_cast<double>(scene.springs.size());
  cl::print_time(result.seconds, result.frames_done, "frame", projections, "spring projection");
  std::printf("\n");

  cl::print_trajectory_note(options, "frame");
  if (!options.summary.empty()) {
    cl::RunSummary summary = cl::stepping_summary(kLab, options.method, scene, particles, strain, result.seconds);
    summary.iterations = options.iterations;
    summary.extra["substeps"] = lab.substeps;
    // λ/Δt² of the last substep, N, file order (null for pbd: lab 04's step keeps none).
    if (settings.method == cl::lab08::Method::kXpbd && !diverged) {
      summary.extra["multipliers"] = forces;
    } else {
      summary.extra["multipliers"] = nullptr;
    }
    summary.extra["multipliers_unit"] = "N";
    summary.extra["rms_strain_error"] = strain.rms;
    summary.extra["total_stretch"] = stretch;
    if (hanging) summary.extra["hanging_chain_stretch"] = *hanging;
    if (!diverged && result.windows_done > 0) {
      summary.extra["window_seconds"] = window_seconds;
      summary.extra["window_total_stretch"] = result.window_total_stretch;
      summary.extra["window_max_strain_error"] = result.window_max_strain;
    }
    cl::add_energies(summary, kinetic, potential, elastic, result.energy_start);
    cl::add_divergence(summary, result.problem, "diverged_at_frame", result.problem_frame);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  if (lab.sweep_iterations.empty()) return run_one(options, lab);
  cl::refuse_run_flags(options, "only for one run (not with --sweep-iterations)",
                       "a sweep writes a CSV, not a run summary");
  return cl::lab08::run_sweep(kLab, CL_LAB_SCENE_DIR, options, lab);
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 08: XPBD. Runs a scene with PBD (lab 04) or XPBD and writes per-frame strain, stretch and "
      "energy and a summary with the multipliers; or sweeps the iteration count and writes the steady "
      "stretch.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("hanging-chain-20", "xpbd", {"pbd", "xpbd"});
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagMethod | cl::kFlagIterations | cl::kFlagDt | cl::kFlagSteps |
                             cl::kFlagOut | cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  cl::add_live_option(app, live);
  app.add_option("--substeps", lab.substeps, "steps of dt/n per frame")
      .range(1, 1'000'000)
      .capture_default_str();
  app.add_option("--window", lab.window_seconds, "averaging window in seconds for the steady stretch")
      .finite_in(1e-9, 1e9)
      .capture_default_str();
  app.add_option("--sweep-iterations", lab.sweep_iterations,
                 "run the scene once per K in this list (e.g. 1,2,4,8) and write "
                 "stretch_vs_iterations_<method>.csv; --steps is then the most frames a run may take to settle")
      .delimiter(',')
      .range(0, 1'000'000);
  app.add_option("--settle-tolerance", lab.settle_tolerance,
                 "sweeps: a run has settled when the mean total stretch of its last three windows agree to this "
                 "relative spread (0: run all --steps frames)")
      .finite_in(0.0, 1e9)
      .capture_default_str();
  app.modes({{"--sweep-iterations", {"--settle-tolerance"}}}, {});
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
