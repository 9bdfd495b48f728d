#include "experiments.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "common/csv.h"
#include "common/driver.h"
#include "common/output.h"

namespace cl::lab05 {

StepSettings step_settings(const Scene& scene, const CommonOptions& options, const LabOptions& lab, Limit limit) {
  StepSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.iterations = options.iterations;
  settings.limit = limit;
  settings.sigma_min = lab.sigma_min;
  settings.sigma_max = lab.sigma_max;
  return settings;
}

Limit limit_from(const std::string& name) {
  try {
    return parse_limit(name);
  } catch (const std::invalid_argument& error) {
    throw cl::InputError(std::string("--limit: ") + error.what());
  }
}

std::string status_of(const RunResult& result) {
  if (result.problem.empty()) return "ok";
  return "unstable at step " + std::to_string(result.problem_step) + ": " + result.problem;
}

double per_step(const RunResult& result) {
  return result.steps_done > 0 ? result.seconds / result.steps_done : 0.0;
}

std::string band_problem(const RunResult& result, Limit limit, const LabOptions& lab, int iterations) {
  if (limit != Limit::kSprings || !result.problem.empty()) return {};
  const double tolerance = band_tolerance(iterations);
  char text[200];
  if (result.max_strain > lab.sigma_max - 1.0 + tolerance) {
    std::snprintf(text, sizeof text, "strain reached %+.3g at step %d, beyond sigma_max - 1 + 0.5/K = %+.3g: the "
                  "limiter did not hold the band", result.max_strain, result.max_strain_step,
                  lab.sigma_max - 1.0 + tolerance);
    return text;
  }
  if (result.min_strain < lab.sigma_min - 1.0 - tolerance) {
    std::snprintf(text, sizeof text, "strain reached %+.3g at step %d, beyond sigma_min - 1 - 0.5/K = %+.3g: the "
                  "limiter did not hold the band", result.min_strain, result.min_strain_step,
                  lab.sigma_min - 1.0 - tolerance);
    return text;
  }
  return {};
}

bool checks_energy(Limit limit) { return limit == Limit::kNone; }

int compare_limits(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                   const LabOptions& lab) {
  const cl::Scene scene = cl::load_scene_for(options, scene_dir);
  std::vector<Limit> limits;
  for (const std::string& name : lab.compare_limits) limits.push_back(limit_from(name));
  std::vector<LimitedSystem> systems;
  for (const Limit limit : limits) systems.push_back(make_limited_system(scene, limit));
  cl::start_run(options);

  cl::CsvTable series({"limit", "step", "time", "max_strain", "min_strain", "rms_strain_error", "total_energy",
                       "status"});
  cl::CsvTable table({"scene", "limit", "iterations", "sigma_min", "sigma_max", "dt", "steps_done",
                      "max_strain_over_run", "min_strain_over_run", "final_max_strain", "final_min_strain",
                      "seconds", "seconds_per_step", "status"});
  cl::CsvTable shapes({"limit", "spring", "x_i", "y_i", "z_i", "x_j", "y_j", "z_j", "strain"});
  std::printf("%s: scene %s, band [%.4g, %.4g], K = %d, dt = %.4g s, %d steps\n", lab_name, cl::describe(scene).c_str(),
              lab.sigma_min, lab.sigma_max, options.iterations, scene.dt, scene.steps);
  std::printf("%-18s %14s %14s %14s %12s  %s\n", "limit", "max strain", "min strain", "final max", "s/step",
              "status");
  // One run after the other, not in parallel: each one's time per step is the point.
  for (std::size_t r = 0; r < limits.size(); ++r) {
    const Limit limit = limits[r];
    const std::string name = limit_name(limit);
    cl::Particles particles = scene.particles;
    const StepCallback on_step = [&](const StepRecord& record, const cl::Particles&) {
      series.add_row({name, static_cast<long long>(record.step), record.time, record.strain.max,
                      record.strain.min, record.rms_strain_error, record.kinetic + record.potential + record.elastic,
                      record.problem.empty() ? std::string("ok") : "unstable: " + record.problem});
    };
    const RunResult result = run_steps(
        particles, systems[r], step_settings(scene, options, lab, limit), scene.steps, checks_energy(limit), on_step);
    const SignedStrain final_strain = signed_strain(particles.x, systems[r].springs);
    table.add_row({scene.name, name, static_cast<long long>(options.iterations), lab.sigma_min, lab.sigma_max,
                   scene.dt, static_cast<long long>(result.steps_done), result.max_strain, result.min_strain,
                   final_strain.max, final_strain.min, result.seconds, per_step(result), status_of(result)});
    std::printf("%-18s %+14.4e %+14.4e %+14.4e %12.3e  %s\n", name.c_str(), result.max_strain, result.min_strain,
                final_strain.max, per_step(result), status_of(result).c_str());
    if (result.problem.empty()) {
      for (std::size_t s = 0; s < scene.springs.size(); ++s) {
        const cl::Spring& spring = scene.springs[s];
        const Eigen::Vector3d a = particles.x.col(spring.i), b = particles.x.col(spring.j);
        shapes.add_row({name, static_cast<long long>(s), a.x(), a.y(), a.z(), b.x(), b.y(), b.z(),
                        (a - b).norm() / spring.rest_length - 1.0});
      }
    }
  }
  if (!options.out.empty()) {
    series.write(cl::join_path(options.out, "strain_vs_time.csv"));
    table.write(cl::join_path(options.out, "compare_limits.csv"));
    shapes.write(cl::join_path(options.out, "shapes.csv"));
  }
  return 0;
}

namespace {

struct MapCell {
  double stiffness = 0.0;
  double dt = 0.0;
  int steps = 0;
  RunResult unlimited;
  RunResult limited;
  bool limited_run = false;
};

// "stable" (the unlimited run is healthy), "bounded by the limiter" (it blew
// up, the limited run did not, kept the band (springs) and any rise of its
// energy within what the scene can release inside the band), or "blew up"
// (the limited run went wrong too: reported unstable, or finite but outside
// the band or past that energy); `why` says what went wrong last.
std::string cell_verdict(const MapCell& cell, Limit limit, const LabOptions& lab, int iterations,
                         std::string& why) {
  why.clear();
  if (cell.unlimited.problem.empty()) return "stable";
  why = cell.limited.problem.empty() ? band_problem(cell.limited, limit, lab, iterations) : cell.limited.problem;
  if (why.empty() && cell.limited.energy_exceeded_step >= 0 && !energy_contained(cell.limited, true)) {
    char text[160];
    std::snprintf(text, sizeof text, "energy not contained: it rose %.3g J, beyond the %.3g J the scene can release "
                  "inside the band", cell.limited.max_energy_rise, cell.limited.energy_bound);
    why = text;
  }
  if (why.empty()) {
    why = "unlimited: " + cell.unlimited.problem;
    return "bounded by the limiter";
  }
  return "blew up";
}

}  // namespace

int stability_map(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                  const LabOptions& lab) {
  const cl::Scene scene = cl::load_scene_for(options, scene_dir);
  const Limit limit = limit_from(lab.limit);
  if (limit == Limit::kNone) throw cl::InputError("--stability-map: needs a limiter (--limit springs, ...)");
  if (options.dt > 0.0 || options.steps >= 0) {
    throw cl::InputError("--stability-map: takes its steps from --map-dt and --map-seconds, not --dt or --steps");
  }
  if (!options.summary.empty()) throw cl::InputError("--summary: the map writes a CSV, not a run summary");
  // Checked once here, so the parallel runs below cannot fail on the scene.
  (void)make_limited_system(scene, limit);
  cl::start_run(options);

  std::vector<MapCell> cells;
  for (const double stiffness : lab.map_stiffness) {
    for (const double dt : lab.map_dt) {
      MapCell cell;
      cell.stiffness = stiffness;
      cell.dt = dt;
      cell.steps = cl::frames_in(lab.map_seconds, dt);
      cells.push_back(cell);
    }
  }
  // Each cell: the unlimited run, then (if it blew up) the limited one. The
  // cells are independent and shared among the OpenMP threads, most steps first.
  std::vector<double> steps;
  for (const MapCell& cell : cells) steps.push_back(cell.steps);
  cl::run_shared(cl::costliest_first(steps), [&](std::size_t c) {
    MapCell& cell = cells[c];
    cl::Scene stiff = scene;
    for (cl::Spring& spring : stiff.springs) spring.stiffness = cell.stiffness;
    StepSettings settings = step_settings(stiff, options, lab, Limit::kNone);
    settings.dt = cell.dt;
    {
      cl::Particles particles = stiff.particles;
      const LimitedSystem system = make_limited_system(stiff, Limit::kNone);
      cell.unlimited = run_steps(particles, system, settings, cell.steps, true);
    }
    if (!cell.unlimited.problem.empty()) {
      settings.limit = limit;
      cl::Particles particles = stiff.particles;
      const LimitedSystem system = make_limited_system(stiff, limit);
      cell.limited = run_steps(particles, system, settings, cell.steps, false);
      cell.limited_run = true;
    }
  });

  // The explicit step's limit, estimated: Δt ω_max < 2 with ω_max² ≈ 8 k w for
  // a grid node with structural and shear springs (README.md, "Why stiff
  // springs blow up"), w the largest inverse mass.
  const double largest_inv_mass = scene.particles.inv_mass.maxCoeff();
  cl::CsvTable table({"scene", "limit", "iterations", "sigma_min", "sigma_max", "stiffness", "dt",
                      "dt_explicit_estimate", "steps", "verdict", "unlimited_steps_done", "unlimited_max_strain", "unlimited_status",
                      "limited_steps_done", "limited_max_strain", "limited_min_strain", "limited_max_energy_rise",
                      "limited_energy_bound", "limited_status", "why", "seconds"});
  std::printf("%s: scene %s, limit %s, band [%.4g, %.4g], K = %d, %.3g s per cell\n", lab_name,
              cl::describe(scene).c_str(), limit_name(limit), lab.sigma_min, lab.sigma_max,
              options.iterations, lab.map_seconds);
  std::printf("%10s %10s %7s  %-24s %14s  %s\n", "k (N/m)", "dt (s)", "steps", "verdict", "limited max", "why");
  int stable = 0, bounded = 0, blew_up = 0, band_lost = 0, energy_lost = 0;
  for (const MapCell& cell : cells) {
    std::string why;
    const std::string verdict = cell_verdict(cell, limit, lab, options.iterations, why);
    stable += verdict == "stable";
    bounded += verdict == "bounded by the limiter";
    blew_up += verdict == "blew up";
    const bool finite = verdict == "blew up" && cell.limited.problem.empty();
    energy_lost += finite && why.rfind("energy not contained", 0) == 0;
    band_lost += finite && why.rfind("energy not contained", 0) != 0;
    table.add_row({scene.name, limit_name(limit), static_cast<long long>(options.iterations),
                   lab.sigma_min, lab.sigma_max, cell.stiffness, cell.dt,
                   2.0 / std::sqrt(8.0 * cell.stiffness * largest_inv_mass), static_cast<long long>(cell.steps),
                   verdict, static_cast<long long>(cell.unlimited.steps_done), cell.unlimited.max_strain,
                   status_of(cell.unlimited),
                   cell.limited_run ? cl::CsvCell{static_cast<long long>(cell.limited.steps_done)}
                                    : cl::CsvCell{std::string()},
                   cl::cell_if(cell.limited_run, cell.limited.max_strain),
                   cl::cell_if(cell.limited_run, cell.limited.min_strain),
                   cl::cell_if(cell.limited_run, cell.limited.max_energy_rise),
                   cl::cell_if(cell.limited_run, cell.limited.energy_bound),
                   cell.limited_run ? cl::CsvCell{status_of(cell.limited)} : cl::CsvCell{std::string()}, why,
                   cell.unlimited.seconds + cell.limited.seconds});
    char limited_max[32] = "";
    if (cell.limited_run && cell.limited.problem.empty()) {
      std::snprintf(limited_max, sizeof limited_max, "%+.4f", cell.limited.max_strain);
    }
    std::printf("%10.3g %10.3g %7d  %-24s %14s  %s\n", cell.stiffness, cell.dt, cell.steps, verdict.c_str(),
                limited_max, why.c_str());
  }
  std::printf("  %d stable, %d bounded by the limiter, %d blew up (%d of them finite but outside the band", stable,
              bounded, blew_up, band_lost);
  if (energy_lost > 0) std::printf(", %d inside it but past the energy it allows", energy_lost);
  std::printf("), of %zu\n", cells.size());
  if (!options.out.empty()) table.write(cl::join_path(options.out, "stability_map.csv"));
  return 0;
}

}  // namespace cl::lab05
