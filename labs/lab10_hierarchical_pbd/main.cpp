// lab10_hierarchical_pbd: PBD on a cloth with the coarse-to-fine hierarchical
// projection (Müller 2008). Two modes (the experiment in experiments.cpp):
//   run       a scene frame by frame, --levels L, --iterations-per-level K
//             -> per_frame.csv, OBJ frames (--frames N), the run summary
//   --converge  experiment 1: one step from rest, the projections until the
//             max strain reaches each --targets value, for every scene of
//             --sweep-scenes and level count of --sweep-levels
//             -> convergence.csv (every sweep) and to_target.csv
//   --live [PORT]  the scene's frames beside a page in the browser
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/driver.h"
#include "common/hierarchy.h"
#include "common/live.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "experiments.h"
#include "hpbd.h"
#include "simulation.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;
using cl::lab10::LabOptions;
cl::LiveOptions live;  // --live [PORT]: the scene steps beside a page in the browser (./course live)

std::string describe_cloth(const cl::Scene& scene) {
  std::ostringstream text;
  text << scene.name << " (" << scene.grid_nx << " x " << scene.grid_ny << " cloth, " << scene.particles.size()
       << " particles, " << scene.springs.size() << " springs)";
  return text.str();
}

// ------------------------------------------------------------------ one run

int run_one(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  const cl::ClothHierarchy hierarchy = cl::lab10::hierarchy_for(scene, lab.levels);
  cl::lab10::HpbdSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.iterations = cl::lab10::per_level(lab, lab.levels);
  if (live.on) {  // levels, a pin or a held particle change the hierarchy's masses: it is built again
    cl::refuse_run_flags(options, "not with --live (the page shows every frame)", "");
    const int most = cl::max_levels(scene.grid_nx, scene.grid_ny);
    cl::LiveRun run{kLab, cl::lab10::method_name(lab.levels),
                    {{"K", "sweeps per level", 0, 200, 1.0 * settings.iterations.front(), true},
                     {"dt", "s", 1e-4, 0.05, scene.dt}, {"levels", "", 1, 1.0 * most, 1.0 * lab.levels, true}}};
    const Eigen::Matrix3Xd rest = scene.particles.x;  // the coarse levels' rest lengths
    std::optional<cl::ClothHierarchy> live_hierarchy;
    cl::BuiltFor built;  // the hierarchy depends on the masses (pins, held particles) and the levels
    run.changed = [&](const cl::Knobs& knobs) -> std::string {
      if (!built.update(scene.particles.inv_mass, {knobs[2]})) return "";
      live_hierarchy.emplace(cl::build_cloth_hierarchy(scene.grid_nx, scene.grid_ny, rest, scene.particles.inv_mass,
                                                       scene.springs, knobs.integer(2)));
      return "the hierarchy";
    };
    run.step = [&](const cl::Knobs& knobs) {
      settings.iterations.assign(static_cast<std::size_t>(knobs.integer(2)), knobs.integer(0));
      settings.dt = knobs[1];
      cl::lab10::hpbd_step(scene.particles, *live_hierarchy, settings);
      return cl::StepVerdict{};
    };
    return cl::run_live(scene, live, run, options.summary);
  }
  cl::start_run(options);
  const std::string frames_dir = cl::join_path(options.out, "frames");
  if (options.frames > 0) cl::ensure_directory(frames_dir);

  cl::FrameOutput output =
      cl::frame_output(options, kLab, scene, "per_frame.csv", cl::lab10::frame_columns(),
                       "hpbd, " + std::to_string(lab.levels) + (lab.levels == 1 ? " level" : " levels"));
  output.obj_every = options.frames;
  output.obj_dir = frames_dir;

  cl::Particles& particles = scene.particles;
  const cl::lab10::RunResult result =
      cl::lab10::run_frames(particles, hierarchy, settings, scene.steps, nullptr, output);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  const double kinetic = cl::kinetic_energy(particles);
  const double potential = cl::potential_energy(particles, scene.gravity);
  const bool diverged = !result.problem.empty();

  std::printf("%s: scene %s, %d level(s), sweeps per level %s (the cloth first), %d frames of %.4g s\n", kLab,
              describe_cloth(scene).c_str(), lab.levels, cl::lab10::join(settings.iterations).c_str(), scene.steps,
              scene.dt);
  for (int l = 0; l < hierarchy.level_count(); ++l) {
    const cl::HierarchyLevel& level = hierarchy.levels[static_cast<std::size_t>(l)];
    double movable = 0.0;  // kg; a pinned particle's (and what it collects) never moves
    for (const int p : level.particles) movable += level.inv_mass[p] > 0.0 ? 1.0 / level.inv_mass[p] : 0.0;
    std::printf("  level %d: %d x %d particles, %zu %sconstraints, movable mass %.4g kg\n", l, level.nx, level.ny,
                level.springs.size(), l > 0 ? "unilateral " : "", movable);
  }
  if (diverged) {
    cl::print_stopped("DIVERGED", "frame", result.problem_frame, scene.dt, result.problem);
  } else {
    std::printf("  final:   max strain %.3e  rms %.3e\n", strain.max, strain.rms);
    cl::print_energies("energy:  ", kinetic, potential, std::nullopt, result.energy_start);
  }
  std::printf("  %lld projections (%lld per step), time %.3e s: %.3e s per frame", result.projections,
              cl::lab10::projections_per_pass(hierarchy, settings.iterations), result.seconds,
              result.frames_done > 0 ? result.seconds / result.frames_done : 0.0);
  if (result.projections > 0) std::printf(", %.3e s per projection", result.seconds / static_cast<double>(result.projections));
  std::printf("\n");
  if (result.obj_frames > 0) std::printf("  %d OBJ frames in %s\n", result.obj_frames, frames_dir.c_str());
  cl::print_trajectory_note(options);

  if (!options.summary.empty()) {
    cl::RunSummary summary =
        cl::stepping_summary(kLab, cl::lab10::method_name(lab.levels), scene, particles, strain, result.seconds);
    summary.iterations = settings.iterations.front();
    summary.extra["levels"] = lab.levels;
    summary.extra["iterations_per_level"] = settings.iterations;
    summary.extra["projections"] = result.projections;
    summary.extra["rms_strain_error"] = strain.rms;
    cl::add_energies(summary, kinetic, potential, std::nullopt, result.energy_start);
    cl::add_divergence(summary, result.problem, "diverged_at_frame", result.problem_frame);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  if (lab.converge) {
    if (live.on) throw cl::InputError("--live: not with --converge");
    cl::refuse_run_flags(options, "not with --converge", "");
    return cl::lab10::run_converge(kLab, CL_LAB_SCENE_DIR, options, lab);
  }
  if (!lab.sweep_scenes.empty()) throw cl::InputError("--sweep-scenes: only with --converge");
  if (live.on && lab.iterations_per_level.size() > 1) {
    throw cl::InputError("--iterations-per-level: one count with --live (its knob K turns every level's)");
  }
  if (!lab.sweep_levels.empty()) throw cl::InputError("--sweep-levels: only with --converge");
  if (options.frames > 0 && options.out.empty()) {
    throw cl::InputError("--frames: needs --out DIR for the trajectory and the OBJ files");
  }
  return run_one(options, lab);
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 10: hierarchical position based dynamics on a cloth. Runs a scene with a coarse-to-fine "
      "projection, or (--converge) counts the projections one step needs to reach a strain target.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("flat-curtain-64");
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagDt | cl::kFlagSteps | cl::kFlagOut | cl::kFlagSummary |
                             cl::kFlagFrames);
  app.get_option("--frames")
      .description("keep every N-th frame in OUT/trajectory.json and .bin (./course view OUT) and write its OBJ "
                   "mesh into OUT/frames/");
  LabOptions lab;
  cl::add_live_option(app, live);
  app.add_option("--levels", lab.levels, "levels of the hierarchy (1: plain Gauss-Seidel PBD)")
      .range(1, 16)
      .capture_default_str();
  app.add_option("--iterations-per-level", lab.iterations_per_level,
                 "Gauss-Seidel sweeps on each level: one count for all, or one per level, the cloth first "
                 "(--converge: the sweeps on each coarse level)")
      .delimiter(',')
      .range(0, 1'000'000)
      .capture_default_str();
  app.add_flag("--converge", lab.converge,
               "experiment 1: one step from rest, count the projections to each --targets max strain");
  app.add_option("--sweep-scenes", lab.sweep_scenes, "--converge: scenes to measure (default: --scene)")
      .delimiter(',');
  app.add_option("--sweep-levels", lab.sweep_levels, "--converge: level counts to measure (default: --levels)")
      .delimiter(',')
      .range(1, 16);
  app.add_option("--targets", lab.targets, "--converge: max strain targets")
      .delimiter(',')
      .finite_in(1e-12, 1e3)
      .capture_default_str();
  app.add_option("--max-sweeps", lab.max_sweeps, "--converge: the most cloth sweeps per measurement")
      .range(0, 100'000'000)
      .capture_default_str();
  app.add_option("--max-projections", lab.max_projections,
                 "--converge: also stop once the cloth sweeps alone reach this many projections (0: no limit)")
      .finite_in(0.0, 1e15)
      .capture_default_str();
  app.modes({{"--converge", {"--sweep-scenes", "--sweep-levels", "--targets", "--max-sweeps", "--max-projections"}}}, {});
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
