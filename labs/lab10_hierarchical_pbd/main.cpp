// lab10_hierarchical_pbd: PBD on a cloth with the coarse-to-fine hierarchical
// projection (Müller 2008). Two modes:
//   run       a scene frame by frame, --levels L, --iterations-per-level K
//             -> per_frame.csv, OBJ frames (--frames N), the run summary
//   --converge  experiment 1: one step from rest, the projections until the
//             max strain reaches each --targets value, for every scene of
//             --sweep-scenes and level count of --sweep-levels
//             -> convergence.csv (every sweep) and to_target.csv
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/csv.h"
#include "common/driver.h"
#include "common/hierarchy.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "hpbd.h"
#include "simulation.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;

struct LabOptions {
  int levels = 3;
  std::vector<int> iterations_per_level{8};
  bool converge = false;
  std::vector<std::string> sweep_scenes;
  std::vector<int> sweep_levels;
  std::vector<double> targets{0.05, 0.01};
  int max_sweeps = 20000;
  double max_projections = 0.0;  // 0: no limit beyond max_sweeps
};

std::string describe_cloth(const cl::Scene& scene) {
  std::ostringstream text;
  text << scene.name << " (" << scene.grid_nx << " x " << scene.grid_ny << " cloth, " << scene.particles.size()
       << " particles, " << scene.springs.size() << " springs)";
  return text.str();
}

// The summary's method: one level is plain Gauss-Seidel PBD.
const char* method_name(int levels) { return levels == 1 ? "gauss-seidel" : "hierarchical"; }

std::string join(const std::vector<int>& values, const char* separator = ",") {
  std::string text;
  for (const int v : values) text += (text.empty() ? "" : separator) + std::to_string(v);
  return text;
}

cl::ClothHierarchy hierarchy_for(const cl::Scene& scene, int levels) {
  if (scene.grid_nx < 2 || scene.grid_ny < 2) {
    throw cl::InputError("--scene " + scene.name + ": hierarchical PBD needs a cloth grid (a scene with \"cloth\")");
  }
  const int most = cl::max_levels(scene.grid_nx, scene.grid_ny);
  if (levels > most) {
    throw cl::InputError("--levels: " + std::to_string(levels) + " is more than a " + std::to_string(scene.grid_nx) +
                         " x " + std::to_string(scene.grid_ny) + " grid has (at most " + std::to_string(most) + ")");
  }
  return cl::build_cloth_hierarchy(scene.grid_nx, scene.grid_ny, scene.particles.x, scene.particles.inv_mass,
                                   scene.springs, levels);
}

// --iterations-per-level: one count for every level, or one per level (the cloth first).
std::vector<int> per_level(const LabOptions& lab, int levels) {
  const std::vector<int>& given = lab.iterations_per_level;
  if (given.size() == 1) return std::vector<int>(static_cast<std::size_t>(levels), given.front());
  if (static_cast<int>(given.size()) == levels) return given;
  throw cl::InputError("--iterations-per-level: give one count or one per level (" + std::to_string(levels) +
                       "), got " + std::to_string(given.size()));
}

// ------------------------------------------------------------------ one run

int run_one(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  const cl::ClothHierarchy hierarchy = hierarchy_for(scene, lab.levels);
  cl::lab10::HpbdSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.iterations = per_level(lab, lab.levels);
  if (!options.out.empty()) cl::ensure_directory(options.out);
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
              describe_cloth(scene).c_str(), lab.levels, join(settings.iterations).c_str(), scene.steps, scene.dt);
  for (int l = 1; l < hierarchy.level_count(); ++l) {
    const cl::HierarchyLevel& level = hierarchy.levels[static_cast<std::size_t>(l)];
    std::printf("  level %d: %d x %d particles, %zu unilateral constraints\n", l, level.nx, level.ny,
                level.springs.size());
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
        cl::stepping_summary(kLab, method_name(lab.levels), scene, particles, strain, result.seconds);
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

// ------------------------------------------------------------------ experiment 1

// --max-sweeps, or fewer when --max-projections allows fewer sweeps on this cloth.
int sweep_limit(const LabOptions& lab, const cl::Scene& scene) {
  if (!(lab.max_projections > 0.0) || scene.springs.empty()) return lab.max_sweeps;
  const double sweeps = std::floor(lab.max_projections / static_cast<double>(scene.springs.size()));
  return static_cast<int>(std::min(sweeps, static_cast<double>(lab.max_sweeps)));
}

int run_converge(const cl::CommonOptions& options, const LabOptions& lab) {
  const std::vector<std::string> names =
      lab.sweep_scenes.empty() ? std::vector<std::string>{options.scene} : lab.sweep_scenes;
  const std::vector<int> level_counts = lab.sweep_levels.empty() ? std::vector<int>{lab.levels} : lab.sweep_levels;
  if (level_counts.size() > 1 && lab.iterations_per_level.size() != 1) {
    throw cl::InputError("--iterations-per-level: with several --sweep-levels give one count (for every level)");
  }
  std::vector<cl::Scene> scenes;
  for (const std::string& name : names) {
    cl::CommonOptions one = options;
    one.scene = name;
    scenes.push_back(cl::load_scene_for(one, CL_LAB_SCENE_DIR));
    for (const int levels : level_counts) {  // reject bad input before any work
      hierarchy_for(scenes.back(), levels);
      if (per_level(lab, levels).front() < 1) {
        throw cl::InputError("--iterations-per-level: --converge needs at least 1 sweep on the cloth");
      }
    }
  }
  const bool single = scenes.size() == 1 && level_counts.size() == 1;
  if (!options.summary.empty() && !single) {
    throw cl::InputError("--summary: only for one scene and one level count (a sweep writes CSV files)");
  }
  if (!options.out.empty()) cl::ensure_directory(options.out);

  cl::CsvTable samples({"scene", "nx", "levels", "iterations_per_level", "passes", "sweeps", "projections",
                        "seconds", "max_strain", "rms_strain"});
  cl::CsvTable reached({"scene", "nx", "ny", "particles", "springs", "levels", "iterations_per_level",
                        "projections_per_pass", "predicted_max_strain", "target", "reached", "passes", "sweeps",
                        "projections", "seconds", "max_strain", "max_sweeps"});
  std::printf("%s: one step from rest (the scene's dt); coarse-to-fine passes until the cloth's max strain is at "
              "or below each target, measured after every sweep on the cloth (at most %d",
              kLab, lab.max_sweeps);
  if (lab.max_projections > 0.0) std::printf(", and at most %.3g projections of the cloth", lab.max_projections);
  std::printf(")\n");
  std::printf("%-18s %6s %9s %7s %11s %7s %8s %14s %9s\n", "scene", "levels", "K/level", "target", "max_strain",
              "passes", "sweeps", "projections", "seconds");
  for (const cl::Scene& scene : scenes) {
    for (const int levels : level_counts) {
      const cl::ClothHierarchy hierarchy = hierarchy_for(scene, levels);
      const std::vector<int> iterations = per_level(lab, levels);
      const std::string k = join(iterations, "/");  // a CSV cell: no commas
      const int max_sweeps = sweep_limit(lab, scene);
      const cl::lab10::ConvergenceResult result = cl::lab10::converge_one_step(
          scene.particles, hierarchy, scene.dt, scene.gravity, iterations, lab.targets, max_sweeps);
      // About a hundred samples per decade of sweeps keep the CSV small.
      for (const cl::lab10::ConvergenceSample& sample : result.samples) {
        const int step = std::max(1, sample.sweeps / 100);
        if (sample.sweeps % step != 0 && &sample != &result.samples.back()) continue;
        samples.add_row({scene.name, static_cast<long long>(scene.grid_nx), static_cast<long long>(levels), k,
                         static_cast<long long>(sample.passes), static_cast<long long>(sample.sweeps),
                         sample.projections, sample.seconds, sample.strain.max, sample.strain.rms});
      }
      for (const cl::lab10::TargetReached& target : result.targets) {
        const cl::lab10::ConvergenceSample& at = target.reached ? target.at : result.samples.back();
        reached.add_row({scene.name, static_cast<long long>(scene.grid_nx), static_cast<long long>(scene.grid_ny),
                         static_cast<long long>(scene.particles.size()), static_cast<long long>(scene.springs.size()),
                         static_cast<long long>(levels), k, cl::lab10::projections_per_pass(hierarchy, iterations),
                         result.samples.front().strain.max, target.target,
                         std::string(target.reached ? "yes" : "no"), static_cast<long long>(at.passes),
                         static_cast<long long>(at.sweeps), at.projections, at.seconds, at.strain.max,
                         static_cast<long long>(max_sweeps)});
        std::printf("%-18s %6d %9s %7.3g %11.4e %7d %8d %14lld %9.4f%s\n", scene.name.c_str(), levels, k.c_str(),
                    target.target, at.strain.max, at.passes, at.sweeps, at.projections, at.seconds,
                    target.reached ? "" : "  not reached (the sweep limit)");
      }
      if (single && !options.summary.empty()) {
        const cl::lab10::ConvergenceSample& last = result.samples.back();
        cl::RunSummary summary;
        summary.lab = kLab;
        summary.method = method_name(levels);
        summary.scene = scene.name;
        summary.dt = scene.dt;
        summary.steps = 1;
        summary.iterations = last.sweeps;
        summary.positions = scene.particles.x;  // the experiment measures one step; it does not keep it
        summary.max_strain_error = last.strain.max;
        summary.seconds = last.seconds;
        summary.extra["levels"] = levels;
        summary.extra["iterations_per_level"] = iterations;
        summary.extra["passes"] = last.passes;
        summary.extra["projections"] = last.projections;
        summary.extra["rms_strain_error"] = last.strain.rms;
        nlohmann::ordered_json to_target = nlohmann::ordered_json::array();
        for (const cl::lab10::TargetReached& target : result.targets) {
          nlohmann::ordered_json entry = {{"target", target.target}, {"reached", target.reached}};
          if (target.reached) {
            entry["passes"] = target.at.passes;
            entry["sweeps"] = target.at.sweeps;
            entry["projections"] = target.at.projections;
            entry["seconds"] = target.at.seconds;
          }
          to_target.push_back(entry);
        }
        summary.extra["to_target"] = to_target;
        cl::write_summary(options.summary, summary);
      }
    }
  }
  if (!options.out.empty()) {
    samples.write(cl::join_path(options.out, "convergence.csv"));
    reached.write(cl::join_path(options.out, "to_target.csv"));
  }
  return 0;
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  if (lab.converge) {
    cl::refuse_run_flags(options, "not with --converge", "");
    return run_converge(options, lab);
  }
  if (!lab.sweep_scenes.empty()) throw cl::InputError("--sweep-scenes: only with --converge");
  if (!lab.sweep_levels.empty()) throw cl::InputError("--sweep-levels: only with --converge");
  if (options.frames > 0 && options.out.empty()) {
    throw cl::InputError("--frames: needs --out DIR for the trajectory and the OBJ files");
  }
  return run_one(options, lab);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Lab 10: hierarchical position based dynamics on a cloth. Runs a scene with a coarse-to-fine "
               "projection, or (--converge) counts the projections one step needs to reach a strain target.",
               CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("flat-curtain-64");
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagDt | cl::kFlagSteps | cl::kFlagOut | cl::kFlagSummary |
                             cl::kFlagFrames);
  app.get_option("--frames")
      ->description("keep every N-th frame in OUT/trajectory.json and .bin (./course view OUT) and write its OBJ "
                    "mesh into OUT/frames/");
  LabOptions lab;
  app.add_option("--levels", lab.levels, "levels of the hierarchy (1: plain Gauss-Seidel PBD)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  app.add_option("--iterations-per-level", lab.iterations_per_level,
                 "Gauss-Seidel sweeps on each level: one count for all, or one per level, the cloth first "
                 "(--converge: the sweeps on each coarse level)")
      ->delimiter(',')
      ->check(CLI::Range(0, 1'000'000))
      ->capture_default_str();
  app.add_flag("--converge", lab.converge,
               "experiment 1: one step from rest, count the projections to each --targets max strain");
  app.add_option("--sweep-scenes", lab.sweep_scenes, "--converge: scenes to measure (default: --scene)")
      ->delimiter(',');
  app.add_option("--sweep-levels", lab.sweep_levels, "--converge: level counts to measure (default: --levels)")
      ->delimiter(',')
      ->check(CLI::Range(1, 16));
  app.add_option("--targets", lab.targets, "--converge: max strain targets")
      ->delimiter(',')
      ->check(cl::finite_in(1e-12, 1e3))
      ->capture_default_str();
  app.add_option("--max-sweeps", lab.max_sweeps, "--converge: the most cloth sweeps per measurement")
      ->check(CLI::Range(0, 100'000'000))
      ->capture_default_str();
  app.add_option("--max-projections", lab.max_projections,
                 "--converge: also stop once the cloth sweeps alone reach this many projections (0: no limit)")
      ->check(cl::finite_in(0.0, 1e15))
      ->capture_default_str();
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
