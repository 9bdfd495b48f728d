#include "experiments.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <sstream>

#include "common/csv.h"
#include "common/health.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/timer.h"
#include "constrained.h"
#include "pbd.h"
#include "step.h"

namespace cl::lab07 {

std::string describe_constraints(const cl::Scene& scene) {
  std::ostringstream text;
  int hard = 0;
  for (const cl::Spring& s : scene.springs) hard += std::isfinite(s.stiffness) ? 0 : 1;
  text << scene.name << " (" << scene.particles.size() << " particles, " << scene.springs.size() << " springs, "
       << hard << " of them hard)";
  return text.str();
}

void apply_stiffness(cl::Scene& scene, const std::string& stiffness) {
  if (stiffness.empty()) return;
  double k = cl::kInfiniteStiffness;
  if (stiffness != "inf") {
    try {
      std::size_t used = 0;
      k = std::stod(stiffness, &used);
      if (used != stiffness.size()) k = -1.0;
    } catch (const std::exception&) {
      k = -1.0;
    }
    if (!std::isfinite(k) || !(k > 0.0)) {
      throw cl::InputError("--stiffness: must be a finite number > 0 or \"inf\" (got " + stiffness + ")");
    }
  }
  for (cl::Spring& spring : scene.springs) spring.stiffness = k;
}

double spring_energy(const Eigen::Matrix3Xd& x, const std::vector<cl::Spring>& springs,
                     const Eigen::VectorXd& lambda) {
  const bool solved = lambda.size() == static_cast<Eigen::Index>(springs.size());
  double energy = 0.0;
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const cl::Spring& s = springs[e];
    if (!std::isfinite(s.stiffness)) continue;
    if (solved) {
      const double force = lambda[static_cast<Eigen::Index>(e)];
      energy += 0.5 * force * force / s.stiffness;
    } else {
      const double phi = (x.col(s.i) - x.col(s.j)).norm() - s.rest_length;
      energy += 0.5 * s.stiffness * phi * phi;
    }
  }
  return energy;
}

double total_energy(const cl::Particles& particles, const cl::Scene& scene, const Eigen::VectorXd& lambda) {
  return cl::kinetic_energy(particles) + cl::potential_energy(particles, scene.gravity) +
         spring_energy(particles.x, scene.springs, lambda);
}

std::string check_health(const cl::Particles& particles, const cl::Scene& scene, const Eigen::VectorXd& lambda,
                         double energy_start, double scale) {
  std::string problem = cl::health_problem(particles, cl::strain_stats(particles.x, scene.springs));
  if (!problem.empty()) return problem;
  const double rise = total_energy(particles, scene, lambda) - energy_start;
  return cl::energy_rise_problem(rise, scale);
}

namespace {

struct CompareRow {
  std::string method;
  int substeps = 1;
  int iterations = 0;       // PBD sweeps per substep; 0 for the direct solves
  int frames = 0;
  double seconds = 0.0;     // wall time of all frames
  double median_seconds = 0.0;  // median wall time of one frame (robust on a shared machine)
  double mean_max_strain = 0.0;   // mean over frames of the max |φ|/L
  double worst_max_strain = 0.0;
  std::string status = "ok";
};

// Runs `advance` (one frame) for the scene's frames and measures the strain after each.
// `advance` returns an empty string or the reason it could not step, and
// leaves the last step's multipliers in `lambda` (empty for PBD).
template <typename Advance>
CompareRow measure(const cl::Scene& scene, CompareRow row, Advance advance) {
  cl::Particles particles = scene.particles;
  Eigen::VectorXd lambda;
  const double energy_start = total_energy(particles, scene, lambda);
  const double scale = cl::energy_scale(particles, scene.gravity, scene.dt);
  double sum = 0.0;
  std::vector<double> frame_seconds;
  for (int f = 1; f <= scene.steps; ++f) {
    const cl::Timer timer;
    const std::string problem = advance(particles, lambda);
    frame_seconds.push_back(timer.seconds());
    row.seconds += frame_seconds.back();
    if (!problem.empty()) {
      row.status = "singular at frame " + std::to_string(f) + ": " + problem;
      break;
    }
    const std::string health = check_health(particles, scene, lambda, energy_start, scale);
    if (!health.empty()) {
      row.status = "diverged at frame " + std::to_string(f) + ": " + health;
      break;
    }
    const double strain = cl::strain_stats(particles.x, scene.springs).max;
    sum += strain;
    row.worst_max_strain = std::max(row.worst_max_strain, strain);
    row.frames = f;
  }
  row.mean_max_strain = row.frames > 0 ? sum / row.frames : 0.0;
  if (!frame_seconds.empty()) {
    const auto middle = frame_seconds.begin() + static_cast<std::ptrdiff_t>(frame_seconds.size() / 2);
    std::nth_element(frame_seconds.begin(), middle, frame_seconds.end());
    row.median_seconds = *middle;
  }
  return row;
}

}  // namespace

int run_compare(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                const LabOptions& lab) {
  if (lab.stabilize) throw cl::InputError("--stabilize: not with a comparison");
  cl::Scene scene = cl::load_scene_for(options, scene_dir);
  apply_stiffness(scene, lab.stiffness);
  cl::start_run(options);
  const std::vector<int> substeps = lab.compare_substeps.empty() ? std::vector<int>{1} : lab.compare_substeps;
  const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
  const cl::lab04::ConstraintSet pbd_constraints =
      cl::lab04::make_constraint_set(scene.particles.size(), scene.springs);

  std::vector<CompareRow> rows;
  auto pbd_row = [&](int n, int iterations) {
    cl::lab04::PbdSettings settings;
    settings.dt = scene.dt / n;
    settings.gravity = scene.gravity;
    settings.iterations = iterations;
    CompareRow row;
    row.method = "pbd-gauss-seidel";
    row.substeps = n;
    row.iterations = iterations;
    rows.push_back(measure(scene, row, [&](cl::Particles& particles, Eigen::VectorXd&) {
      for (int s = 0; s < n; ++s) cl::lab04::pbd_step(particles, pbd_constraints, settings);
      return std::string();
    }));
  };
  for (const int k : lab.compare_pbd) pbd_row(1, k);
  for (const int n : substeps) {
    if (n > 1) pbd_row(n, 1);
  }
  for (const bool stabilized : {false, true}) {
  for (const Method method : {Method::kSchur, Method::kKkt}) {
    if (stabilized && method == Method::kKkt) continue;
    for (const int n : substeps) {
      StepSettings settings;
      settings.dt = scene.dt / n;
      settings.gravity = scene.gravity;
      settings.method = method;
      settings.regularization = lab.regularize;
      CompareRow row;
      row.method = method == Method::kKkt ? "kkt" : (stabilized ? "schur-stabilized" : "schur");
      row.substeps = n;
      rows.push_back(measure(scene, row, [&](cl::Particles& particles, Eigen::VectorXd& lambda) {
        for (int s = 0; s < n; ++s) {
          StepResult result = constrained_step(particles, scene.springs, map, settings);
          if (!result.ok) return result.problem;
          lambda = std::move(result.lambda);
          if (stabilized) {
            const ProjectionResult projection =
                stabilize_positions(particles, scene.springs, map);
            if (!projection.ok) return projection.problem;
          }
        }
        return std::string();
      }));
    }
  }
  }

  cl::CsvTable table({"scene", "method", "dt", "substeps", "iterations", "frames", "median_ms_per_frame", "mean_max_strain",
                      "worst_max_strain", "status"});
  std::printf("%s: scene %s, %d frames of %.4g s; strain = max over springs of |phi|/L after each frame\n", lab_name,
              describe_constraints(scene).c_str(), scene.steps, scene.dt);
  std::printf("%-17s %8s %10s %12s %15s %15s  %s\n", "method", "substeps", "iterations", "median ms/frame", "mean max strain",
              "worst", "status");
  for (const CompareRow& row : rows) {
    const double ms = 1e3 * row.median_seconds;
    table.add_row({scene.name, row.method, scene.dt, static_cast<long long>(row.substeps),
                   static_cast<long long>(row.iterations), static_cast<long long>(row.frames), ms,
                   row.mean_max_strain, row.worst_max_strain, row.status});
    std::printf("%-17s %8d %10d %12.4f %15.4e %15.4e  %s\n", row.method.c_str(), row.substeps, row.iterations, ms,
                row.mean_max_strain, row.worst_max_strain, row.status.c_str());
  }
  if (!options.out.empty()) table.write(cl::join_path(options.out, "compare.csv"));
  return 0;
}

}  // namespace cl::lab07
