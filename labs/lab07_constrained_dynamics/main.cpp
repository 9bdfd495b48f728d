// lab07_constrained_dynamics: implicit Euler with linearised distance
// constraints, solved as one KKT system (--method kkt) or by its Schur
// complement (--method schur). Per-frame constraint error and energy
// (per_frame.csv), the run summary with the multipliers; and one comparison
// (experiments.cpp):
//   --compare-pbd 1,4,16 --compare-substeps 1,2,4   PBD (lab 04) against this
//                                                   lab's two solves -> compare.csv
//   --live [PORT]   the scene's steps beside a page in the browser (run.cpp)
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/driver.h"
#include "common/frame_loop.h"
#include "common/health.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "common/timer.h"
#include "constrained.h"
#include "experiments.h"
#include "pbd.h"
#include "run.h"
#include "step.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;
using cl::lab07::LabOptions;
cl::LiveOptions live;  // --live [PORT]: the scene steps beside a page in the browser (./course live)

// ------------------------------------------------------------------ one run

int run_one(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  cl::lab07::apply_stiffness(scene, lab.stiffness);
  cl::start_run(options);

  cl::lab07::StepSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.method = options.method == "kkt" ? cl::lab07::Method::kKkt : cl::lab07::Method::kSchur;
  settings.regularization = lab.regularize;
  const bool compliance_block = cl::lab07::compliance_of(scene.springs, lab.regularize).size() > 0;

  cl::Particles& particles = scene.particles;
  const cl::MovableMap map = cl::make_movable_map(particles.inv_mass);
  Eigen::VectorXd lambda;  // the last successful step's (empty before one)
  const double energy_start = cl::lab07::total_energy(particles, scene, lambda);
  const double scale = cl::energy_scale(particles, scene.gravity, scene.dt);
  const bool redundant = cl::lab07::hard_constraints_redundant(particles, scene.springs, map);

  // One step: the solve, then (--stabilize) the projection onto the hard
  // constraints; the loop's clock times both.
  double solve_seconds = 0.0, step_seconds = 0.0, stabilize_seconds = 0.0, projection_seconds = 0.0;
  double worst_error = 0.0, worst_before_projection = 0.0;
  auto step = [&](int) -> cl::StepVerdict {
    projection_seconds = 0.0;
    const cl::Timer step_timer;
    const cl::lab07::StepResult result = cl::lab07::constrained_step(particles, scene.springs, map, settings);
    solve_seconds = step_timer.seconds();
    step_seconds += solve_seconds;
    if (!result.ok) return {"singular: " + result.problem, false};
    lambda = result.lambda;
    if (lab.stabilize) {
      worst_before_projection =
          std::max(worst_before_projection, cl::lab07::max_constraint_error(particles.x, scene.springs));
      const cl::Timer projection_timer;
      const cl::lab07::ProjectionResult projection = cl::lab07::stabilize_positions(particles, scene.springs, map);
      projection_seconds = projection_timer.seconds();
      stabilize_seconds += projection_seconds;
      if (!projection.ok) return {"singular: " + projection.problem, false};
    }
    // Over every step taken, the one a run stops at included.
    worst_error = std::max(worst_error, cl::lab07::max_constraint_error(particles.x, scene.springs));
    return {};
  };
  auto measure = [&](int frame, double) {
    const double kinetic = cl::kinetic_energy(particles);
    const double potential = cl::potential_energy(particles, scene.gravity);
    const double elastic = cl::lab07::spring_energy(particles.x, scene.springs, lambda);
    const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
    const double total = kinetic + potential + elastic;
    return cl::FrameMeasure{strain, total, {},
                            {cl::lab07::max_constraint_error(particles.x, scene.springs), strain.max, kinetic,
                             potential, elastic, total, frame > 0 ? solve_seconds : 0.0, projection_seconds},
                            {}};
  };
  const cl::FramePlan plan = cl::frame_plan(scene.steps, scene.dt, scale);
  cl::FrameOutput output = cl::frame_output(options, kLab, scene, "per_frame.csv",
                                            {"max_constraint_error", "max_strain", "kinetic", "potential",
                                             "spring_energy", "total_energy", "step_seconds", "stabilize_seconds"},
                                            options.method + (lab.stabilize ? ", stabilized" : ""));
  const cl::FrameLoopResult run = cl::run_frame_loop(particles, step, measure, plan, output);
  const int frames_done = run.frames_done;
  const int problem_frame = run.problem_frame;
  const std::string outcome = run.problem.empty() ? std::string() : run.status;  // "diverged: …" or "singular: …"

  const bool stopped = !outcome.empty();
  const double final_error = cl::lab07::max_constraint_error(particles.x, scene.springs);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  std::printf("%s: scene %s, %s, dt %.4g s, %d steps%s%s\n", kLab, cl::lab07::describe_constraints(scene).c_str(),
              options.method.c_str(), scene.dt, scene.steps, lab.stabilize ? ", stabilized" : "",
              compliance_block ? "" : ", no compliance block (every constraint hard)");
  if (redundant) {
    std::printf("  the hard constraints are redundant at the start (J W J^T singular): lambda is not unique%s\n",
                lab.regularize > 0.0 ? " without the regularization" : "");
  }
  if (lab.regularize > 0.0) {
    std::printf("  regularized: every hard constraint has compliance %.3g m/N (a %.3g N/m spring)\n",
                lab.regularize, 1.0 / lab.regularize);
  }
  if (stopped) {
    cl::print_stopped("STOPPED", "step", problem_frame, scene.dt, outcome);
    if (outcome.rfind("singular", 0) == 0) {
      std::printf("  the state before that step is kept; --regularize EPS (e.g. 1e-9 m/N) makes every hard "
                  "constraint a stiff spring and the system solvable\n");
    }
  }
  if (!stopped || frames_done > 0) {
    std::printf("  max |phi| %.3e m at the end, %.3e m worst over the run%s; max strain %.3e\n", final_error,
                worst_error, lab.stabilize ? " (after projection)" : "", strain.max);
    if (lab.stabilize) std::printf("  worst max |phi| before the projection: %.3e m\n", worst_before_projection);
    const double energy = cl::lab07::total_energy(particles, scene, lambda);
    std::printf("  energy: %.6e J (start %.6e J)\n", energy, energy_start);
  }
  const double steps_taken = std::max(1, frames_done);
  std::printf("  time %.3e s: %.3e s per step%s\n", run.seconds, run.seconds / steps_taken,
              lab.stabilize ? " (the solve and the projection)" : "");
  if (lab.stabilize) std::printf("  projection %.3e s per step (%.0f%% of the step)\n", stabilize_seconds / steps_taken,
                                 run.seconds > 0.0 ? 100.0 * stabilize_seconds / run.seconds : 0.0);
  cl::print_multipliers(lambda);

  cl::print_trajectory_note(options, "frame");
  if (!options.summary.empty()) {
    cl::RunSummary summary = cl::stepping_summary(kLab, options.method, scene, particles, strain, run.seconds);
    summary.extra["multipliers"] = std::vector<double>(lambda.data(), lambda.data() + lambda.size());
    summary.extra["max_constraint_error"] = final_error;
    summary.extra["worst_constraint_error"] = worst_error;
    summary.extra["stabilize"] = lab.stabilize;
    if (lab.stabilize) {
      summary.extra["worst_constraint_error_before_projection"] = worst_before_projection;
      summary.extra["stabilize_seconds"] = stabilize_seconds;
    }
    summary.extra["regularization"] = lab.regularize;
    summary.extra["redundant_at_start"] = redundant;
    summary.extra["compliance_block"] = compliance_block;
    summary.extra["steps_done"] = frames_done;
    summary.extra["step_seconds"] = step_seconds;
    cl::add_total_energy(summary, cl::lab07::total_energy(particles, scene, lambda), energy_start);
    cl::add_stop_outcome(summary, outcome, "singular", problem_frame);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  const bool compare = !lab.compare_pbd.empty() || !lab.compare_substeps.empty();
  if (live.on && compare) throw cl::InputError("--live: not with --compare-pbd or --compare-substeps");
  if (live.on) return cl::lab07::run_live_scene(kLab, CL_LAB_SCENE_DIR, options, lab, live);
  if (!compare) return run_one(options, lab);
  cl::refuse_run_flags(options, "only for one run (not with --compare-pbd or --compare-substeps)",
                       "a comparison writes compare.csv, not a run summary");
  return cl::lab07::run_compare(kLab, CL_LAB_SCENE_DIR, options, lab);
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 07: constrained dynamics. Implicit Euler with linearised distance constraints, solved as one "
      "KKT system or by its Schur complement; writes per-frame constraint error and energy and a summary "
      "with the multipliers. Or compares PBD (lab 04) with both solves on one scene.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("ragdoll-chain-20", "schur", {"kkt", "schur"});
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagMethod | cl::kFlagDt | cl::kFlagSteps | cl::kFlagOut |
                             cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  cl::add_live_option(app, live);
  app.add_flag("--stabilize", lab.stabilize,
               "after every step, project the positions once onto the hard constraints (velocities unchanged)");
  app.add_option("--regularize", lab.regularize,
                 "compliance (m/N) added to every hard constraint, e.g. 1e-9: a way out of a singular system")
      .non_negative();
  app.add_option("--stiffness", lab.stiffness, "replace every spring's stiffness: a number (N/m) or inf");
  app.add_option("--compare-pbd", lab.compare_pbd,
                 "compare: PBD (lab 04, Gauss-Seidel) with these iteration counts, one substep; writes compare.csv")
      .delimiter(',')
      .range(1, 1'000'000);
  app.add_option("--compare-substeps", lab.compare_substeps,
                 "compare: the KKT and Schur steps (and PBD with one iteration) at these substeps per frame")
      .delimiter(',')
      .range(1, 1'000'000);
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
