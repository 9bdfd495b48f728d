#include "common/driver.h"

#include <cmath>
#include <cstdio>
#include <utility>

#include "common/output.h"

namespace cl {

FrameOutput frame_output(const CommonOptions& options, const char* lab, const Scene& scene, const char* csv_name,
                         std::vector<std::string> columns, std::string method) {
  FrameOutput output;
  if (!options.out.empty()) output.csv_path = join_path(options.out, csv_name);
  output.columns = std::move(columns);
  output.lab = lab;
  output.scene = &scene;
  output.trajectory_every = options.frames;
  output.trajectory_dir = options.out;
  output.method = std::move(method);
  return output;
}

std::vector<Scene> load_scenes(const CommonOptions& options, const std::vector<std::string>& names,
                               const std::string& lab_scene_dir) {
  std::vector<Scene> scenes;
  for (const std::string& name : names.empty() ? std::vector<std::string>{options.scene} : names) {
    CommonOptions one = options;
    one.scene = name;
    scenes.push_back(load_scene_for(one, lab_scene_dir, names.empty() ? "--scene" : "--sweep-scenes"));
  }
  return scenes;
}

void refuse_run_flags(const CommonOptions& options, const std::string& frames_why, const std::string& summary_why) {
  if (options.frames > 0 && !frames_why.empty()) throw InputError("--frames: " + frames_why);
  if (!options.summary.empty() && !summary_why.empty()) throw InputError("--summary: " + summary_why);
}

void require_finite_springs(const Scene& scene, const std::string& why) {
  for (std::size_t e = 0; e < scene.springs.size(); ++e) {
    if (!std::isfinite(scene.springs[e].stiffness)) {
      throw InputError(scene.source + ": springs[" + std::to_string(e) + "].stiffness: inf is a hard constraint; " +
                       why);
    }
  }
}

std::string settle_status(const std::string& problem, int frame, bool settled) {
  if (!problem.empty()) return "diverged at frame " + std::to_string(frame) + ": " + problem;
  return settled ? "settled" : "not settled";
}

std::vector<std::size_t> costliest_first(const std::vector<double>& costs) {
  std::vector<std::size_t> order(costs.size());
  for (std::size_t r = 0; r < order.size(); ++r) order[r] = r;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return costs[a] > costs[b]; });
  return order;
}

void print_time(double seconds, int steps, const char* step, double work, const char* work_unit) {
  std::printf("  time %.3e s: %.3e s per %s", seconds, steps > 0 ? seconds / steps : 0.0, step);
  if (work > 0) std::printf(", %.3e s per %s", seconds / work, work_unit);
}

void print_stopped(const char* verdict, const char* unit, int at, double dt, const std::string& problem) {
  std::printf("  %s at %s %d (t = %.4g s): %s\n", verdict, unit, at, at * dt, problem.c_str());
}

void print_energies(const char* label, double kinetic, double potential, std::optional<double> elastic,
                    double total_start) {
  double total = kinetic + potential;
  std::printf("  %skinetic %.4e J  potential %.4e J", label, kinetic, potential);
  if (elastic) {
    std::printf("  elastic %.4e J", *elastic);
    total += *elastic;
  }
  std::printf("  total %.6e J (start %.6e J)\n", total, total_start);
}

bool print_multipliers(const Eigen::VectorXd& lambda) {
  if (lambda.size() == 0 || lambda.size() > 4) return false;
  std::printf("  multipliers (N):");
  for (Eigen::Index e = 0; e < lambda.size(); ++e) std::printf(" %.6g", lambda[e]);
  std::printf("\n");
  return true;
}

void print_trajectory_note(const CommonOptions& options, const char* frame) {
  if (options.frames <= 0) return;
  std::printf("  trajectory: %s/trajectory.{json,bin}, %s 0, %d, %d, ... and the last (./course view %s)\n",
              options.out.c_str(), frame, options.frames, 2 * options.frames, options.out.c_str());
}

}  // namespace cl
