// lab13_constrained_newton: the compliant implicit-Euler step by Newton's
// method on the constrained system (x and λ), down to hard springs; lab 06's
// Newton and PD on the same scene for comparison.
//   default        run the scene's steps: per_step.csv, iterations.csv (every
//                  iteration of every step) and the run summary (run.cpp);
//                  --live: the same steps beside a page in the browser
//   --convergence  one step to its converged result against k, per method,
//                  start and warm start: convergence.csv, crossover.csv
#include <string>

#include "common/cli.h"
#include "common/live.h"
#include "common/sparse.h"
#include "experiments.h"
#include "run.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;
cl::LiveOptions live;  // --live [PORT]: the scene steps beside a page in the browser (./course live)

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 13: the implicit-Euler step by Newton's method on the constrained system (x and lambda), from soft "
      "springs to hard ones. Runs a scene, or (--convergence) one step of it to convergence against k.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options =
      cl::lab_defaults("pd-curtain-16", "constrained-newton", {"constrained-newton", "newton", "pd"});
  options.iterations = 10;
  cl::add_common_options(app, options, cl::kFlagScene | cl::kFlagMethod | cl::kFlagIterations | cl::kFlagDt |
                                           cl::kFlagSteps | cl::kFlagOut | cl::kFlagSummary | cl::kFlagFrames);
  cl::lab13::LabOptions lab;
  cl::add_live_option(app, live);
  std::string start = "x", warm = "forces", compression = "keep";
  app.add_option("--start", start, "constrained-newton's first iterate: x (the step's start) or prediction (y)")
      .one_of({"x", "prediction"}).capture_default_str().only_for_methods({"constrained-newton"});
  app.add_option("--warm", warm, "constrained-newton's first multipliers: forces (the springs' at the start) or zero")
      .one_of({"forces", "zero"}).capture_default_str().only_for_methods({"constrained-newton"});
  app.add_option("--tolerance", lab.settings.tolerance,
                 "constrained-newton: stop once the force and constraint errors are both below this (0: every iteration)")
      .non_negative().capture_default_str().only_for_methods({"constrained-newton"});
  app.add_option("--stiffness", lab.stiffness, "every spring's stiffness, N/m, or inf (hard); default: the scene's");
  app.add_option("--compression", compression,
                 "compressed springs in K_g: keep (exact; dropped where not definite) or drop (always)")
      .one_of({"drop", "keep"}).capture_default_str().only_for_methods({"constrained-newton"});
  app.add_flag("--convergence", lab.convergence, "one step to convergence against k: convergence.csv, crossover.csv");
  app.add_option("--sweep-scenes", lab.sweep_scenes, "--convergence: the scenes (default: --scene)").delimiter(',');
  app.add_option("--stiffnesses", lab.stiffnesses, "--convergence: the stiffnesses, N/m or inf").delimiter(',')
      .capture_default_str();
  app.add_option("--starts", lab.starts, "--convergence: constrained-newton's first iterates (x, prediction)")
      .delimiter(',').capture_default_str();
  app.add_option("--warms", lab.warms, "--convergence: constrained-newton's warm starts (forces, zero)")
      .delimiter(',').capture_default_str();
  app.add_option("--warmup", lab.warmup, "--convergence: constrained Newton steps before the measured one")
      .range(0, 100000).capture_default_str();
  app.add_option("--newton-cap", lab.newton_cap, "--convergence: the most Newton iterations (both Newtons)")
      .range(1, 100000).capture_default_str();
  app.add_option("--pd-cap", lab.pd_cap, "--convergence: the most PD iterations").range(1, 1000000).capture_default_str();
  app.modes({{"--convergence", {"--sweep-scenes", "--stiffnesses", "--starts", "--warms", "--warmup", "--newton-cap",
                                 "--pd-cap"}}},
            {"--method", "--iterations", "--tolerance", "--steps", "--start", "--warm", "--summary",
             "--frames", "--live"});
  return cl::run_main(app, argc, argv, [&] {
    // CHOLMOD's BLAS on one thread: the solves are small, OpenBLAS's idle
    // threads spin (half of a 32² run's time went to sched_yield), and the
    // experiment times serial methods side by side, as the bench does.
    cl::set_blas_threads(1);
    lab.settings.start = cl::lab13::start_from_name(start);
    lab.settings.warm = cl::lab13::warm_from_name(warm);
    lab.settings.compression = compression == "keep" ? cl::lab09::Compression::kKeep : cl::lab09::Compression::kDrop;
    if (!lab.stiffness.empty()) cl::lab13::parse_stiffness("--stiffness", lab.stiffness);
    if (!lab.convergence && !lab.sweep_scenes.empty()) throw cl::InputError("--sweep-scenes: only with --convergence");
    if (lab.convergence) {
      if (live.on) throw cl::InputError("--live: not with --convergence (it runs one step per k)");
      if (!lab.stiffness.empty()) throw cl::InputError("--stiffness: --convergence sweeps --stiffnesses instead");
      return cl::lab13::run_convergence(kLab, CL_LAB_SCENE_DIR, options, lab);
    }
    return cl::lab13::run_scene(kLab, CL_LAB_SCENE_DIR, options, lab, live);
  });
}
