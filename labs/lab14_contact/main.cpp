// lab14_contact: a scene with colliders, stepped by PBD (lab 04), XPBD (lab 08)
// or lab 07's constrained step with the contact rows solved by projected
// Gauss-Seidel: per_step.csv (contacts found and active, penetration, normal
// forces, stick and slide, particles moved back, energy) and the run summary.
// The experiments (experiments.cpp):
//   --drape     every method × --frictions on the scene: drape.csv
//   --incline   the stick/slip boundary against μ per method: incline.csv
//   --live      the scene steps beside a page in the browser (./course live)
#include <cstdio>
#include <optional>
#include <string>

#include "common/cli.h"
#include "common/driver.h"
#include "common/live.h"
#include "common/output.h"
#include "common/sparse.h"
#include "common/summary.h"
#include "contact_step.h"
#include "experiments.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;
using cl::lab14::LabOptions;
cl::LiveOptions live;  // --live [PORT]

// --live: K, dt and mu (every collider's, as --friction sets it); a change of
// one, a pin or a held particle builds the stepper again.
int run_live(const cl::CommonOptions& options, const LabOptions& lab, cl::Scene& scene) {
  cl::refuse_run_flags(options, "not with --live (the page shows every step)", "");
  const double mu = lab.friction ? *lab.friction : (scene.colliders.empty() ? 0.0 : scene.colliders[0].friction);
  cl::LiveRun run{kLab, options.method, {{"K", "iterations", 1, 200, 1.0 * options.iterations, true},
                                         {"dt", "s", 1e-4, 0.05, scene.dt}, {"mu", "", 0, 2, mu}}};
  cl::lab14::StepSettings settings = cl::lab14::step_settings(scene, options, lab);
  std::optional<cl::lab14::ContactStepper> stepper;
  run.changed = [&](const cl::Knobs& knobs) -> std::string {  // the stepper holds K, dt and mu: built again
    settings.iterations = knobs.integer(0);
    settings.dt = knobs[1];
    settings.friction = knobs[2];
    stepper.emplace(scene, settings);
    return "the contact stepper";
  };
  run.step = [&](const cl::Knobs&) {
    const cl::lab14::StepReport report = stepper->step(scene.particles);
    return cl::StepVerdict{report.problem, report.problem.empty()};
  };
  return cl::run_live(scene, live, run, options.summary);
}

int run_one(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  const cl::lab14::StepSettings settings = cl::lab14::step_settings(scene, options, lab);
  // --check stops here: the initial penetration pass below runs your surface_distance.
  if (live.on) cl::stop_if_checking(); else cl::start_run(options);
  const cl::lab14::InitialPenetration initial = cl::lab14::resolve_initial_penetration(scene.particles,
                                                                                       scene.colliders);
  if (initial.particles > 0) cl::lab14::report_initial_penetration(kLab, initial);
  if (live.on) return run_live(options, lab, scene);
  cl::lab14::ContactStepper stepper(scene, settings);
  cl::FrameOutput output =
      cl::frame_output(options, kLab, scene, "per_step.csv", cl::lab14::step_columns(), options.method);
  output.index_column = "step";
  cl::Particles& particles = scene.particles;
  const Eigen::Vector3d centre_start = cl::lab14::centre_of_mass(particles);
  const cl::lab14::RunResult result =
      cl::lab14::run_steps(particles, stepper, scene.springs, scene.colliders, scene.steps, nullptr, output);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  const double steps_done = result.steps_done > 0 ? result.steps_done : 1.0;
  const double found_per_step = static_cast<double>(result.contacts) / steps_done;
  const double active_per_step = static_cast<double>(result.active) / steps_done;

  std::printf("%s: scene %s, %zu collider(s), %s, K = %d, friction %s, %d steps of %.4g s\n", kLab,
              cl::describe(scene).c_str(), scene.colliders.size(), options.method.c_str(), options.iterations,
              lab.friction ? std::to_string(*lab.friction).c_str() : "the colliders'", scene.steps, scene.dt);
  if (!result.problem.empty()) {
    cl::print_stopped(result.step_failed ? "STOPPED" : "DIVERGED", "step", result.problem_step, scene.dt,
                      result.problem);
  }
  std::printf("  contacts per step: %.1f found, %.1f active (λ_n > 0); %lld swept, %lld sticking and %lld sliding "
              "contact-steps; %lld particle-steps moved back from inside a collider\n",
              found_per_step, active_per_step, result.swept, result.sticking, result.sliding, result.moved_back);
  if (result.unsettled_steps > 0) {
    std::printf("  %lld step(s) ended with the springs' rows still moving (their 4th pass moved an end by up to "
                "%.3g m, above 1e-5 m)\n", result.unsettled_steps, result.max_unsettled);
  }
  std::printf("  worst penetration %.3e m, largest normal force %.6g N, max strain %.3e\n", result.max_penetration,
              result.max_normal_force, strain.max);
  cl::print_energies("  energy: ", cl::kinetic_energy(particles), cl::potential_energy(particles, scene.gravity),
                     std::nullopt, result.energy_start);
  cl::print_time(result.seconds, result.steps_done, "step");
  std::printf("\n");
  cl::print_trajectory_note(options, "step");
  if (!options.summary.empty()) {
    cl::RunSummary summary = cl::stepping_summary(kLab, options.method, scene, particles, strain, result.seconds);
    summary.iterations = options.iterations;
    if (lab.friction) summary.extra["friction"] = *lab.friction;
    summary.extra["contacts_found_per_step"] = found_per_step;
    summary.extra["contacts_active_per_step"] = active_per_step;
    summary.extra["moved_back"] = result.moved_back;
    summary.extra["swept_contacts"] = result.swept;
    summary.extra["sticking"] = result.sticking;
    summary.extra["sliding"] = result.sliding;
    summary.extra["max_penetration"] = result.max_penetration;
    summary.extra["unsettled_steps"] = result.unsettled_steps;
    summary.extra["initial_penetration"] = initial.deepest;        // m, before the load moved them out
    summary.extra["initial_penetration_particles"] = initial.particles;
    summary.extra["max_normal_force"] = result.max_normal_force;
    summary.extra["centre_of_mass_drift"] =  // m, sideways: 0 while a mirror-symmetric run stays symmetric
        cl::lab14::sideways_drift(centre_start, cl::lab14::centre_of_mass(particles), scene.gravity);
    cl::add_energies(summary, cl::kinetic_energy(particles), cl::potential_energy(particles, scene.gravity),
                     std::nullopt, result.energy_start);
    cl::add_stop_outcome(summary, result.problem.empty() ? "" : (result.step_failed ? result.problem : "diverged: " + result.problem),
                         "singular", result.problem_step);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 14: contact with planes, spheres and capsules, with Coulomb friction, by PBD, XPBD or the constrained "
      "step with projected Gauss-Seidel. Runs a scene, or one of the experiments (--drape, --incline).",
      CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults(cl::lab14::kDefaultScene, "pbd", {"pbd", "xpbd", "constrained"});
  options.iterations = 10;
  options.models_colliders = true;
  cl::add_common_options(app, options, cl::kFlagScene | cl::kFlagMethod | cl::kFlagIterations | cl::kFlagDt |
                                           cl::kFlagSteps | cl::kFlagOut | cl::kFlagSummary | cl::kFlagFrames);
  app.get_option("--iterations").range(1, 100000).description("pbd/xpbd: sweeps and contact passes; constrained: "
                                                               "block iterations (1 to 100000)");
  LabOptions lab;
  cl::add_live_option(app, live);
  // μ above kMaxFriction sticks every contact as firmly as any larger one
  // would; the cap keeps μ λ_n and μ d finite for any force a step can reach.
  app.add_option("--friction", lab.friction, "Coulomb's mu for every collider, in [0, 1e6] (default: each collider's own)")
      .finite_in(0.0, cl::lab14::kMaxFriction);
  const cl::Option method = app.get_option("--method");  // the experiments run every method
  app.add_flag("--drape", lab.drape, "experiment 1: every method x --frictions on the scene -> drape.csv")
      .excludes(method);
  app.add_flag("--incline", lab.incline, "experiment 2: the stick/slip boundary against mu per method -> incline.csv")
      .excludes(method);
  // The lists are read whole (check_lab_options): an empty entry is refused, not skipped.
  app.add_option("--frictions", lab.frictions_given, "--drape, --incline: the friction coefficients (default 0,0.3,1)");
  app.add_option("--angles", lab.angles_given, "--incline: the incline's angles, degrees in (0, 90) (default: 16 "
                                               "around atan 0.3 and atan 1)");
  return cl::run_main(app, argc, argv, [&] {
    cl::set_blas_threads(1);  // CHOLMOD's BLAS: small solves, and idle OpenBLAS threads spin (lab 13)
    cl::lab14::check_lab_options(lab);
    if (live.on && (lab.drape || lab.incline)) throw cl::InputError("--live: not with --drape or --incline");
    if (lab.drape && lab.incline) throw cl::InputError("--incline: not together with --drape");
    if (lab.drape) return cl::lab14::run_drape(kLab, CL_LAB_SCENE_DIR, options, lab);
    if (lab.incline) return cl::lab14::run_incline(kLab, options, lab);
    return run_one(options, lab);
  });
}
