// lab09_stable_constrained: lab 07's constrained step with the geometric
// stiffness K_g of the distance constraints (--geometric-stiffness on|off),
// solved as one KKT system (--method kkt) or by a Schur complement (--method
// schur). Per-frame constraint error, transverse speed and energy
// (per_frame.csv) and the run summary with the multipliers; and one experiment
// (experiments.cpp):
//   --sweep-mass-ratios 1,10,...   largest stable dt of a heavy chain against its
//                                  mass ratio, with and without K_g -> stability.csv,
//                                  stability_runs.csv
//   --live [PORT]                  the scene's steps beside a page in the browser (run.cpp)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/csv.h"
#include "common/driver.h"
#include "common/frame_loop.h"
#include "common/health.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "experiments.h"
#include "geometric_stiffness.h"
#include "run.h"
#include "stable_step.h"
#include "step.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;
using cl::lab09::LabOptions;
cl::LiveOptions live;  // --live [PORT]: the scene steps beside a page in the browser (./course live)

std::string describe_constraints_and_masses(const cl::Scene& scene) {
  std::ostringstream text;
  int hard = 0;
  for (const cl::Spring& s : scene.springs) hard += std::isfinite(s.stiffness) ? 0 : 1;
  double lightest = 0.0, heaviest = 0.0;
  for (Eigen::Index p = 0; p < scene.particles.size(); ++p) {
    const double w = scene.particles.inv_mass[p];
    if (!(w > 0.0)) continue;
    lightest = lightest == 0.0 ? 1.0 / w : std::min(lightest, 1.0 / w);
    heaviest = std::max(heaviest, 1.0 / w);
  }
  text << scene.name << " (" << scene.particles.size() << " particles, " << scene.springs.size() << " springs, "
       << hard << " of them hard";
  if (lightest > 0.0) text << ", mass ratio " << heaviest / lightest;
  text << ")";
  return text.str();
}

// ------------------------------------------------------------------ one run

int run_one(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  cl::start_run(options);
  const cl::lab09::StableSettings settings =
      cl::lab09::settings_for(scene, options, lab, lab.geometric_stiffness == "on");

  cl::Particles& particles = scene.particles;
  const cl::MovableMap map = cl::make_movable_map(particles.inv_mass);
  const double energy_start = cl::lab09::total_energy(particles, scene);
  const double scale = cl::energy_scale(particles, scene.gravity, scene.dt);
  const auto m = static_cast<Eigen::Index>(scene.springs.size());

  Eigen::VectorXd lambda;  // the previous step's multipliers (none before the first step)
  double worst_transverse = cl::lab09::max_transverse_speed(particles, scene.springs);
  auto step = [&](int) -> cl::StepVerdict {
    const cl::lab09::StableStepResult result = cl::lab09::stable_step(particles, scene.springs, map, settings, lambda);
    if (!result.ok) return {"failed: " + result.problem, false};
    lambda = result.lambda;
    worst_transverse = std::max(worst_transverse, cl::lab09::max_transverse_speed(particles, scene.springs));
    return {};
  };
  auto measure = [&](int, double seconds) {
    const double kinetic = cl::kinetic_energy(particles);
    const double potential = cl::potential_energy(particles, scene.gravity);
    const double elastic = cl::lab09::spring_energy(particles.x, scene.springs);
    const bool known = lambda.size() == m && m > 0;
    return cl::FrameMeasure{cl::strain_stats(particles.x, scene.springs), kinetic + potential + elastic, {},
                            {cl::lab07::max_constraint_error(particles.x, scene.springs),
                             cl::lab09::max_transverse_speed(particles, scene.springs),
                             known ? cl::CsvCell{lambda.minCoeff()} : cl::CsvCell{std::string()},
                             known ? cl::CsvCell{lambda.maxCoeff()} : cl::CsvCell{std::string()}, kinetic, potential,
                             elastic, kinetic + potential + elastic, seconds},
                            {}};
  };
  const cl::FramePlan plan = cl::frame_plan(scene.steps, scene.dt, scale);
  cl::FrameOutput output = cl::frame_output(options, kLab, scene, "per_frame.csv",
                                            {"max_constraint_error", "max_transverse_speed", "min_lambda", "max_lambda",
                                             "kinetic", "potential", "spring_energy", "total_energy", "step_seconds"},
                                            options.method + ", K_g " + lab.geometric_stiffness);
  const cl::FrameLoopResult run = cl::run_frame_loop(particles, step, measure, plan, output);
  const int frames_done = run.frames_done;
  const int problem_frame = run.problem_frame;
  const double seconds = run.seconds;
  const std::string outcome = run.problem.empty() ? std::string() : run.status;  // "diverged: …" or "failed: …"

  const bool stopped = !outcome.empty();
  const bool finite = cl::all_finite(particles.x) && cl::all_finite(particles.v);
  const double final_error = cl::lab07::max_constraint_error(particles.x, scene.springs);
  const double final_transverse = cl::lab09::max_transverse_speed(particles, scene.springs);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  std::printf("%s: scene %s, %s, geometric stiffness %s (compression: %s), dt %.4g s, %d steps\n", kLab,
              describe_constraints_and_masses(scene).c_str(), options.method.c_str(), lab.geometric_stiffness.c_str(),
              lab.compression.c_str(), scene.dt, scene.steps);
  if (stopped) {
    cl::print_stopped("STOPPED", "step", problem_frame, scene.dt, outcome);
  }
  if (finite) {
    std::printf("  transverse speed: %.3e m/s at the end, %.3e m/s the most over the run\n", final_transverse,
                worst_transverse);
    std::printf("  max |phi| %.3e m at the end; max strain %.3e\n", final_error, strain.max);
    std::printf("  energy: %.6e J (start %.6e J)\n", cl::lab09::total_energy(particles, scene), energy_start);
  }
  std::printf("  time %.3e s: %.3e s per step\n", seconds, seconds / std::max(1, frames_done));
  if (!cl::print_multipliers(lambda) && lambda.size() > 4) {
    std::printf("  multipliers from %.6g N to %.6g N (negative: tension)\n", lambda.minCoeff(), lambda.maxCoeff());
  }

  cl::print_trajectory_note(options, "frame");
  if (!options.summary.empty()) {
    cl::RunSummary summary = cl::stepping_summary(kLab, options.method, scene, particles, strain, seconds);
    summary.extra["geometric_stiffness"] = lab.geometric_stiffness;
    summary.extra["compression"] = lab.compression;
    summary.extra["multipliers"] = std::vector<double>(lambda.data(), lambda.data() + lambda.size());
    summary.extra["max_constraint_error"] = final_error;
    summary.extra["max_transverse_speed"] = worst_transverse;
    summary.extra["final_transverse_speed"] = final_transverse;
    summary.extra["regularization"] = lab.regularize;
    summary.extra["steps_done"] = frames_done;
    cl::add_total_energy(summary, cl::lab09::total_energy(particles, scene), energy_start);
    cl::add_stop_outcome(summary, outcome, "failed", problem_frame);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  if (live.on && !lab.sweep_mass_ratios.empty()) throw cl::InputError("--live: not with --sweep-mass-ratios");
  if (live.on) return cl::lab09::run_live_scene(kLab, CL_LAB_SCENE_DIR, options, lab, live);
  if (lab.sweep_mass_ratios.empty()) return run_one(options, lab);
  cl::refuse_run_flags(options, "only for one run (not with --sweep-mass-ratios)",
                       "a sweep writes stability.csv, not a run summary");
  return cl::lab09::run_sweep(kLab, options, lab);
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 09: stable constrained dynamics. Lab 07's step with the geometric stiffness of the distance "
      "constraints, solved as one KKT system or by a Schur complement; writes per-frame constraint error, "
      "transverse speed and energy and a summary with the multipliers. Or measures the largest stable "
      "dt of a heavy chain against its mass ratio, with and without the geometric stiffness.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("heavy-chain-1000", "schur", {"schur", "kkt"});
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagMethod | cl::kFlagDt | cl::kFlagSteps | cl::kFlagOut |
                             cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  cl::add_live_option(app, live);
  app.add_option("--geometric-stiffness", lab.geometric_stiffness,
                 "add K_g to the step (on) or not (off: lab 07's step)")
      .one_of({"on", "off"})
      .capture_default_str();
  app.add_option("--compression", lab.compression,
                 "compressed constraints (lambda > 0) in K_g: drop them (always SPD) or keep them (exact, may be "
                 "indefinite)")
      .one_of({"drop", "keep"})
      .capture_default_str();
  app.add_option("--regularize", lab.regularize,
                 "compliance (m/N) added to every hard constraint, as in lab 07 (e.g. 1e-9)")
      .non_negative();
  app.add_option("--sweep-mass-ratios", lab.sweep_mass_ratios,
                 "experiment: for each mass ratio (e.g. 1,10,100) find the largest stable dt of the heavy chain "
                 "with and without K_g; writes stability.csv and stability_runs.csv")
      .delimiter(',')
      .finite_in(1e-6, 1e12);
  app.add_option("--sweep-dt-min", lab.sweep_dt_min, "experiment: the smallest dt tried (s)")
      .finite_in(1e-7, 10.0)
      .capture_default_str();
  app.add_option("--sweep-dt-max", lab.sweep_dt_max, "experiment: the largest dt tried (s)")
      .finite_in(1e-7, 10.0)
      .capture_default_str();
  app.add_option("--sweep-per-decade", lab.sweep_per_decade, "experiment: dt values per decade")
      .range(1, 1000)
      .capture_default_str();
  app.add_option("--sweep-links", lab.sweep_links, "experiment: links in the chain")
      .range(2, 10000)
      .capture_default_str();
  app.modes({{"--sweep-mass-ratios", {"--sweep-dt-min", "--sweep-dt-max", "--sweep-per-decade", "--sweep-links"}}}, {});
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
