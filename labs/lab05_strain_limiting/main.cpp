// lab05_strain_limiting: a mass-spring cloth stepped explicitly, with a strain
// limiter after every step: per-step strain and energy (per_step.csv) and the
// run summary. Two experiments, one invocation each:
//   --compare-limits none,springs,...   the scene once per limiter -> strain_vs_time.csv,
//                                        compare_limits.csv, shapes.csv
//   --stability-map                      stiffness × Δt, each cell unlimited and
//                                        limited                   -> stability_map.csv
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/csv.h"
#include "common/driver.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "simulation.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;
using cl::lab05::Limit;

struct LabOptions {
  std::string limit = "springs";
  double sigma_min = 0.9;
  double sigma_max = 1.1;
  std::vector<std::string> compare_limits;
  bool stability_map = false;
  std::vector<double> map_stiffness{1e1, 1e2, 1e3, 1e4, 1e5, 1e6};
  std::vector<double> map_dt{1e-4, 5e-4, 2e-3, 1e-2, 1.0 / 30.0};
  double map_seconds = 1.0;
};

cl::lab05::StepSettings step_settings(const cl::Scene& scene, const cl::CommonOptions& options,
                                      const LabOptions& lab, Limit limit) {
  cl::lab05::StepSettings settings;
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
    return cl::lab05::parse_limit(name);
  } catch (const std::invalid_argument& error) {
    throw cl::InputError(std::string("--limit: ") + error.what());
  }
}

std::string status_of(const cl::lab05::RunResult& result) {
  if (result.problem.empty()) return "ok";
  return "unstable at step " + std::to_string(result.problem_step) + ": " + result.problem;
}

double per_step(const cl::lab05::RunResult& result) {
  return result.steps_done > 0 ? result.seconds / result.steps_done : 0.0;
}

// Empty when a spring-limited run kept every spring inside the band, up to
// band_tolerance(K), for the whole run; otherwise one line saying how far out
// it went. Triangle limiters bound triangles, not springs: nothing to check.
std::string band_problem(const cl::lab05::RunResult& result, Limit limit, const LabOptions& lab, int iterations) {
  if (limit != Limit::kSprings || !result.problem.empty()) return {};
  const double tolerance = cl::lab05::band_tolerance(iterations);
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

// Unlimited runs are checked for energy as well: that is how an explicit step
// that blows up is caught before its strain reaches kUnstableStrain. Limited
// runs are not (README.md, "Bounded only by the limiter").
bool checks_energy(Limit limit) { return limit == Limit::kNone; }

// ------------------------------------------------------------------ one run

int run_one(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  const Limit limit = limit_from(lab.limit);
  const cl::lab05::LimitedSystem system = cl::lab05::make_limited_system(scene, limit);
  if (!options.out.empty()) cl::ensure_directory(options.out);
  const cl::lab05::StepSettings settings = step_settings(scene, options, lab, limit);

  cl::FrameOutput output =
      cl::frame_output(options, kLab, scene, "per_step.csv", cl::lab05::step_columns(), "limit " + lab.limit);
  cl::Particles& particles = scene.particles;
  const cl::lab05::RunResult result =
      cl::lab05::run_steps(particles, system, settings, scene.steps, checks_energy(limit), nullptr, output);
  const bool diverged = !result.problem.empty();
  const cl::lab05::SignedStrain strain = cl::lab05::signed_strain(particles.x, system.springs);
  const cl::StrainStats error = cl::strain_stats(particles.x, system.springs);
  const double kinetic = cl::kinetic_energy(particles);
  const double potential = cl::potential_energy(particles, scene.gravity);
  const double elastic = cl::lab05::elastic_energy(particles.x, system.springs);

  std::printf("%s: scene %s, limit %s, band [%.4g, %.4g], K = %d, dt = %.4g s, %d steps\n", kLab,
              cl::describe(scene).c_str(), cl::lab05::limit_name(limit), lab.sigma_min, lab.sigma_max,
              options.iterations, scene.dt, scene.steps);
  if (diverged) {
    cl::print_stopped("UNSTABLE", "step", result.problem_step, scene.dt, result.problem);
  } else {
    std::printf("  final:      strain (l/L - 1) from %+.4e to %+.4e\n", strain.min, strain.max);
    std::printf("  whole run:  strain from %+.4e to %+.4e\n", result.min_strain, result.max_strain);
    cl::print_energies("energy:     ", kinetic, potential, elastic, result.energy_start);
  }
  const std::string outside = band_problem(result, limit, lab, options.iterations);
  if (!outside.empty()) std::printf("  WARNING: %s\n", outside.c_str());
  cl::print_trajectory_note(options, "step");
  cl::print_time(result.seconds, result.steps_done, "step");
  std::printf("\n");
  // A limited run whose energy rose past the scene's scale and did not stop:
  // only the limiter holds it (README.md, "Bounded only by the limiter").
  const bool contained = limit != Limit::kNone && result.energy_exceeded_step >= 0 && !diverged;
  if (contained) {
    std::fprintf(stderr, "%s: bounded only by the limiter: from step %d (t = %.4g s) the total energy rose up to "
                 "%.3g J above its start, more than the scene's %.3g J; the run went on, held inside the band by "
                 "the limiter alone (summary: energy_contained_by_limiter)\n", kLab, result.energy_exceeded_step,
                 result.energy_exceeded_step * scene.dt, result.max_energy_rise, result.energy_scale);
  }
  if (!options.summary.empty()) {
    cl::RunSummary summary =
        cl::stepping_summary(kLab, cl::lab05::limit_name(limit), scene, particles, error, result.seconds);
    summary.iterations = options.iterations;
    summary.extra["limit"] = cl::lab05::limit_name(limit);
    summary.extra["sigma_min"] = lab.sigma_min;
    summary.extra["sigma_max"] = lab.sigma_max;
    summary.extra["max_strain"] = strain.max;
    summary.extra["min_strain"] = strain.min;
    summary.extra["max_strain_over_run"] = result.max_strain;
    summary.extra["min_strain_over_run"] = result.min_strain;
    summary.extra["rms_strain_error"] = error.rms;
    summary.extra["seconds_per_step"] = per_step(result);
    cl::add_energies(summary, kinetic, potential, elastic, result.energy_start);
    if (limit == Limit::kSprings) summary.extra["band_held"] = outside.empty() && !diverged;
    if (limit != Limit::kNone) summary.extra["energy_contained_by_limiter"] = contained;
    if (contained) summary.extra["energy_contained_from_step"] = result.energy_exceeded_step;
    cl::add_divergence(summary, result.problem, "diverged_at_step", result.problem_step);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

// ------------------------------------------------------------------ experiment 1

int compare_limits(const cl::CommonOptions& options, const LabOptions& lab) {
  const cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  std::vector<Limit> limits;
  for (const std::string& name : lab.compare_limits) limits.push_back(limit_from(name));
  std::vector<cl::lab05::LimitedSystem> systems;
  for (const Limit limit : limits) systems.push_back(cl::lab05::make_limited_system(scene, limit));
  if (!options.out.empty()) cl::ensure_directory(options.out);

  cl::CsvTable series({"limit", "step", "time", "max_strain", "min_strain", "rms_strain_error", "total_energy",
                       "status"});
  cl::CsvTable table({"scene", "limit", "iterations", "sigma_min", "sigma_max", "dt", "steps_done",
                      "max_strain_over_run", "min_strain_over_run", "final_max_strain", "final_min_strain",
                      "seconds", "seconds_per_step", "status"});
  cl::CsvTable shapes({"limit", "spring", "x_i", "y_i", "z_i", "x_j", "y_j", "z_j", "strain"});
  std::printf("%s: scene %s, band [%.4g, %.4g], K = %d, dt = %.4g s, %d steps\n", kLab, cl::describe(scene).c_str(),
              lab.sigma_min, lab.sigma_max, options.iterations, scene.dt, scene.steps);
  std::printf("%-18s %14s %14s %14s %12s  %s\n", "limit", "max strain", "min strain", "final max", "s/step",
              "status");
  // One run after the other, not in parallel: each one's time per step is the point.
  for (std::size_t r = 0; r < limits.size(); ++r) {
    const Limit limit = limits[r];
    const std::string name = cl::lab05::limit_name(limit);
    cl::Particles particles = scene.particles;
    const cl::lab05::StepCallback on_step = [&](const cl::lab05::StepRecord& record, const cl::Particles&) {
      series.add_row({name, static_cast<long long>(record.step), record.time, record.strain.max,
                      record.strain.min, record.rms_strain_error, record.kinetic + record.potential + record.elastic,
                      record.problem.empty() ? std::string("ok") : "unstable: " + record.problem});
    };
    const cl::lab05::RunResult result = cl::lab05::run_steps(
        particles, systems[r], step_settings(scene, options, lab, limit), scene.steps, checks_energy(limit), on_step);
    const cl::lab05::SignedStrain final_strain = cl::lab05::signed_strain(particles.x, systems[r].springs);
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

// ------------------------------------------------------------------ experiment 2

struct MapCell {
  double stiffness = 0.0;
  double dt = 0.0;
  int steps = 0;
  cl::lab05::RunResult unlimited;
  cl::lab05::RunResult limited;
  bool limited_run = false;
};

// "stable" (the unlimited run is healthy), "bounded by the limiter" (it blew
// up, the limited run did not and, for springs, kept the band), or "blew up"
// (the limited run went wrong too: reported unstable, or finite but outside
// the band); `why` says what went wrong last.
std::string cell_verdict(const MapCell& cell, Limit limit, const LabOptions& lab, int iterations,
                         std::string& why) {
  why.clear();
  if (cell.unlimited.problem.empty()) return "stable";
  why = cell.limited.problem.empty() ? band_problem(cell.limited, limit, lab, iterations) : cell.limited.problem;
  if (why.empty()) {
    why = "unlimited: " + cell.unlimited.problem;
    return "bounded by the limiter";
  }
  return "blew up";
}

int stability_map(const cl::CommonOptions& options, const LabOptions& lab) {
  const cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  const Limit limit = limit_from(lab.limit);
  if (limit == Limit::kNone) throw cl::InputError("--stability-map: needs a limiter (--limit springs, ...)");
  if (options.dt > 0.0 || options.steps >= 0) {
    throw cl::InputError("--stability-map: takes its steps from --map-dt and --map-seconds, not --dt or --steps");
  }
  if (!options.summary.empty()) throw cl::InputError("--summary: the map writes a CSV, not a run summary");
  // Checked once here, so the parallel runs below cannot fail on the scene.
  (void)cl::lab05::make_limited_system(scene, limit);
  if (!options.out.empty()) cl::ensure_directory(options.out);

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
    cl::lab05::StepSettings settings = step_settings(stiff, options, lab, Limit::kNone);
    settings.dt = cell.dt;
    {
      cl::Particles particles = stiff.particles;
      const cl::lab05::LimitedSystem system = cl::lab05::make_limited_system(stiff, Limit::kNone);
      cell.unlimited = cl::lab05::run_steps(particles, system, settings, cell.steps, true);
    }
    if (!cell.unlimited.problem.empty()) {
      settings.limit = limit;
      cl::Particles particles = stiff.particles;
      const cl::lab05::LimitedSystem system = cl::lab05::make_limited_system(stiff, limit);
      cell.limited = cl::lab05::run_steps(particles, system, settings, cell.steps, false);
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
                      "limited_status", "why", "seconds"});
  std::printf("%s: scene %s, limit %s, band [%.4g, %.4g], K = %d, %.3g s per cell\n", kLab,
              cl::describe(scene).c_str(), cl::lab05::limit_name(limit), lab.sigma_min, lab.sigma_max,
              options.iterations, lab.map_seconds);
  std::printf("%10s %10s %7s  %-24s %14s  %s\n", "k (N/m)", "dt (s)", "steps", "verdict", "limited max", "why");
  int stable = 0, bounded = 0, blew_up = 0, band_lost = 0;
  for (const MapCell& cell : cells) {
    std::string why;
    const std::string verdict = cell_verdict(cell, limit, lab, options.iterations, why);
    stable += verdict == "stable";
    bounded += verdict == "bounded by the limiter";
    blew_up += verdict == "blew up";
    band_lost += verdict == "blew up" && cell.limited.problem.empty();
    table.add_row({scene.name, cl::lab05::limit_name(limit), static_cast<long long>(options.iterations),
                   lab.sigma_min, lab.sigma_max, cell.stiffness, cell.dt,
                   2.0 / std::sqrt(8.0 * cell.stiffness * largest_inv_mass), static_cast<long long>(cell.steps),
                   verdict, static_cast<long long>(cell.unlimited.steps_done), cell.unlimited.max_strain,
                   status_of(cell.unlimited),
                   cell.limited_run ? cl::CsvCell{static_cast<long long>(cell.limited.steps_done)}
                                    : cl::CsvCell{std::string()},
                   cl::cell_if(cell.limited_run, cell.limited.max_strain),
                   cl::cell_if(cell.limited_run, cell.limited.min_strain),
                   cl::cell_if(cell.limited_run, cell.limited.max_energy_rise),
                   cell.limited_run ? cl::CsvCell{status_of(cell.limited)} : cl::CsvCell{std::string()}, why,
                   cell.unlimited.seconds + cell.limited.seconds});
    char limited_max[32] = "";
    if (cell.limited_run && cell.limited.problem.empty()) {
      std::snprintf(limited_max, sizeof limited_max, "%+.4f", cell.limited.max_strain);
    }
    std::printf("%10.3g %10.3g %7d  %-24s %14s  %s\n", cell.stiffness, cell.dt, cell.steps, verdict.c_str(),
                limited_max, why.c_str());
  }
  std::printf("  %d stable, %d bounded by the limiter, %d blew up (%d of them finite but outside the band), of %zu\n",
              stable, bounded, blew_up, band_lost, cells.size());
  if (!options.out.empty()) table.write(cl::join_path(options.out, "stability_map.csv"));
  return 0;
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  if (lab.sigma_min > lab.sigma_max) {
    char text[160];
    std::snprintf(text, sizeof text, "--sigma-min %.10g is above --sigma-max %.10g (the band must not be empty)",
                  lab.sigma_min, lab.sigma_max);
    throw cl::InputError(text);
  }
  if (lab.stability_map && !lab.compare_limits.empty()) {
    throw cl::InputError("--stability-map: not with --compare-limits (one experiment per run)");
  }
  if (lab.stability_map || !lab.compare_limits.empty()) {
    cl::refuse_run_flags(options, "only for one run (not with --stability-map or --compare-limits)", "");
  }
  if (lab.stability_map) return stability_map(options, lab);
  if (!lab.compare_limits.empty()) {
    cl::refuse_run_flags(options, "", "--compare-limits writes CSVs, not a run summary");
    return compare_limits(options, lab);
  }
  return run_one(options, lab);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Lab 05: strain limiting. Steps a mass-spring scene explicitly and limits the strain of its springs "
               "or triangles to [sigma-min, sigma-max] after every step; writes per-step strain and energy and a "
               "summary. Or compares the limiters, or maps stability over stiffness and dt.",
               CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("soft-curtain-32");
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagIterations | cl::kFlagDt | cl::kFlagSteps | cl::kFlagOut |
                             cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  app.add_option("--limit", lab.limit, "the limiter run after each step")
      ->check(CLI::IsMember({"none", "springs", "triangles-area", "triangles-stretch"}))
      ->capture_default_str();
  app.add_option("--sigma-min", lab.sigma_min, "lower bound of the band for l/L (> 0)")
      ->check(cl::finite_number(false))
      ->capture_default_str();
  app.add_option("--sigma-max", lab.sigma_max, "upper bound of the band for l/L (>= sigma-min)")
      ->check(cl::finite_number(false))
      ->capture_default_str();
  app.add_option("--compare-limits", lab.compare_limits,
                 "run the scene once per limiter in this list (e.g. none,springs,triangles-area,triangles-stretch) "
                 "and write strain_vs_time.csv, compare_limits.csv and shapes.csv")
      ->delimiter(',')
      ->check(CLI::IsMember({"none", "springs", "triangles-area", "triangles-stretch"}));
  app.add_flag("--stability-map", lab.stability_map,
               "run the scene at every (--map-stiffness, --map-dt) pair, without a limiter and, where that blows "
               "up, with --limit; write stability_map.csv");
  app.add_option("--map-stiffness", lab.map_stiffness, "spring stiffnesses (N/m) for --stability-map")
      ->delimiter(',')
      ->check(cl::finite_number(false))
      ->capture_default_str();
  app.add_option("--map-dt", lab.map_dt, "time steps (s) for --stability-map")
      ->delimiter(',')
      ->check(cl::finite_number(false))
      ->capture_default_str();
  app.add_option("--map-seconds", lab.map_seconds, "simulated time per --stability-map run (s)")
      ->check(cl::finite_in(1e-9, 1e6))
      ->capture_default_str();
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
