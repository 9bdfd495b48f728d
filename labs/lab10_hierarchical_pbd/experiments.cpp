#include "experiments.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/csv.h"
#include "common/driver.h"
#include "common/output.h"
#include "common/summary.h"
#include "hpbd.h"
#include "simulation.h"

namespace cl::lab10 {

const char* method_name(int levels) { return levels == 1 ? "gauss-seidel" : "hierarchical"; }

std::string join(const std::vector<int>& values, const char* separator) {
  std::string text;
  for (const int v : values) text += (text.empty() ? "" : separator) + std::to_string(v);
  return text;
}

ClothHierarchy hierarchy_for(const Scene& scene, int levels, const std::string& flag) {
  if (scene.grid_nx < 2 || scene.grid_ny < 2) {
    throw cl::InputError("--scene " + scene.name + ": hierarchical PBD needs a cloth grid (a scene with \"cloth\")");
  }
  const int most = cl::max_levels(scene.grid_nx, scene.grid_ny);
  if (levels > most) {
    throw cl::InputError(flag + ": " + std::to_string(levels) + " is more than a " + std::to_string(scene.grid_nx) +
                         " x " + std::to_string(scene.grid_ny) + " grid has (at most " + std::to_string(most) + ")");
  }
  return cl::build_cloth_hierarchy(scene.grid_nx, scene.grid_ny, scene.particles.x, scene.particles.inv_mass,
                                   scene.springs, levels);
}

std::vector<int> per_level(const LabOptions& lab, int levels) {
  const std::vector<int>& given = lab.iterations_per_level;
  if (given.size() == 1) return std::vector<int>(static_cast<std::size_t>(levels), given.front());
  if (static_cast<int>(given.size()) == levels) return given;
  throw cl::InputError("--iterations-per-level: give one count or one per level (" + std::to_string(levels) +
                       "), got " + std::to_string(given.size()));
}

namespace {

// --max-sweeps, or fewer when --max-projections allows fewer sweeps on this cloth.
int sweep_limit(const LabOptions& lab, const cl::Scene& scene) {
  if (!(lab.max_projections > 0.0) || scene.springs.empty()) return lab.max_sweeps;
  const double sweeps = std::floor(lab.max_projections / static_cast<double>(scene.springs.size()));
  return static_cast<int>(std::min(sweeps, static_cast<double>(lab.max_sweeps)));
}

}  // namespace

int run_converge(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                 const LabOptions& lab) {
  const std::vector<int> level_counts = lab.sweep_levels.empty() ? std::vector<int>{lab.levels} : lab.sweep_levels;
  const std::string levels_flag = lab.sweep_levels.empty() ? "--levels" : "--sweep-levels";
  if (level_counts.size() > 1 && lab.iterations_per_level.size() != 1) {
    throw cl::InputError("--iterations-per-level: with several --sweep-levels give one count (for every level)");
  }
  const std::vector<cl::Scene> scenes = cl::load_scenes(options, lab.sweep_scenes, scene_dir);
  for (const cl::Scene& scene : scenes) {
    for (const int levels : level_counts) {  // reject bad input before any work
      hierarchy_for(scene, levels, levels_flag);
      if (per_level(lab, levels).front() < 1) {
        throw cl::InputError("--iterations-per-level: --converge needs at least 1 sweep on the cloth");
      }
    }
  }
  const bool single = scenes.size() == 1 && level_counts.size() == 1;
  if (!options.summary.empty() && !single) {
    throw cl::InputError("--summary: only for one scene and one level count (a sweep writes CSV files)");
  }
  cl::start_run(options);

  cl::CsvTable samples({"scene", "nx", "levels", "iterations_per_level", "passes", "sweeps", "projections",
                        "seconds", "max_strain", "rms_strain"});
  cl::CsvTable reached({"scene", "nx", "ny", "particles", "springs", "levels", "iterations_per_level",
                        "projections_per_pass", "predicted_max_strain", "target", "reached", "passes", "sweeps",
                        "projections", "seconds", "max_strain", "max_sweeps"});
  std::printf("%s: one step from rest (the scene's dt); coarse-to-fine passes until the cloth's max strain is at "
              "or below each target, measured after every sweep on the cloth (at most %d",
              lab_name, lab.max_sweeps);
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
      // Which cap stops a measurement that does not reach its target.
      const char* limit = max_sweeps < lab.max_sweeps ? "--max-projections" : "--max-sweeps";
      const ConvergenceResult result = converge_one_step(
          scene.particles, hierarchy, scene.dt, scene.gravity, iterations, lab.targets, max_sweeps);
      // Every sweep below 200, then every (sweeps / 100)-th: the rows thin out as the sweeps grow.
      for (const ConvergenceSample& sample : result.samples) {
        const int step = std::max(1, sample.sweeps / 100);
        if (sample.sweeps % step != 0 && &sample != &result.samples.back()) continue;
        samples.add_row({scene.name, static_cast<long long>(scene.grid_nx), static_cast<long long>(levels), k,
                         static_cast<long long>(sample.passes), static_cast<long long>(sample.sweeps),
                         sample.projections, sample.seconds, sample.strain.max, sample.strain.rms});
      }
      for (const TargetReached& target : result.targets) {
        const ConvergenceSample& at = target.reached ? target.at : result.samples.back();
        reached.add_row({scene.name, static_cast<long long>(scene.grid_nx), static_cast<long long>(scene.grid_ny),
                         static_cast<long long>(scene.particles.size()), static_cast<long long>(scene.springs.size()),
                         static_cast<long long>(levels), k, projections_per_pass(hierarchy, iterations),
                         result.samples.front().strain.max, target.target,
                         std::string(target.reached ? "yes" : "no"), static_cast<long long>(at.passes),
                         static_cast<long long>(at.sweeps), at.projections, at.seconds, at.strain.max,
                         static_cast<long long>(max_sweeps)});
        std::printf("%-18s %6d %9s %7.3g %11.4e %7d %8d %14lld %9.4f%s\n", scene.name.c_str(), levels, k.c_str(),
                    target.target, at.strain.max, at.passes, at.sweeps, at.projections, at.seconds,
                    target.reached ? "" : (std::string("  not reached (the limit of ") + limit + ")").c_str());
      }
      if (single && !options.summary.empty()) {
        const ConvergenceSample& last = result.samples.back();
        cl::RunSummary summary;
        summary.lab = lab_name;
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
        for (const TargetReached& target : result.targets) {
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

}  // namespace cl::lab10
