// lab07_constrained_dynamics: implicit Euler with linearised distance
// constraints, solved as one KKT system (--method kkt) or by its Schur
// complement (--method schur). Per-frame constraint error and energy
// (per_frame.csv), the run summary with the multipliers; and one comparison:
//   --compare-pbd 1,4,16 --compare-substeps 1,2,4   PBD (lab 04) against this
//                                                   lab's two solves -> compare.csv
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
#include "common/timer.h"
#include "constrained.h"
#include "pbd.h"
#include "step.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;

struct LabOptions {
  bool stabilize = false;
  double regularize = 0.0;          // m/N on every hard constraint
  std::string stiffness;            // empty: the scene's; else a number (N/m) or "inf" for every spring
  std::vector<int> compare_pbd;     // PBD iteration counts (one substep)
  std::vector<int> compare_substeps;
};

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

// The energy stored in the springs of finite stiffness (J). After a step it is
// the energy the step solved for, ½ Σ c_e λ_e² = ½ Σ λ_e²/k_e (λ = −k times the
// LINEARISED stretch); before the first step, ½ Σ k φ². The two differ by the
// linearisation error: on a 1e12 N/m spring a drift of 5 µm would count 12 J
// that no force ever stored (the next step treats it like a hard constraint's drift).
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

// Empty when healthy: finite, strain below cl::kUnstableStrain, energy not
// risen by more than the scene's scale (implicit Euler only loses energy).
std::string check_health(const cl::Particles& particles, const cl::Scene& scene, const Eigen::VectorXd& lambda,
                         double energy_start, double scale) {
  std::string problem = cl::health_problem(particles, cl::strain_stats(particles.x, scene.springs));
  if (!problem.empty()) return problem;
  const double rise = total_energy(particles, scene, lambda) - energy_start;
  return cl::energy_rise_problem(rise, scale);
}

// ------------------------------------------------------------------ one run

int run_one(const cl::CommonOptions& options, const LabOptions& lab) {
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  apply_stiffness(scene, lab.stiffness);
  if (!options.out.empty()) cl::ensure_directory(options.out);

  cl::lab07::StepSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.method = options.method == "kkt" ? cl::lab07::Method::kKkt : cl::lab07::Method::kSchur;
  settings.regularization = lab.regularize;
  const bool compliance_block = cl::lab07::compliance_of(scene.springs, lab.regularize).size() > 0;

  cl::Particles& particles = scene.particles;
  const cl::MovableMap map = cl::make_movable_map(particles.inv_mass);
  Eigen::VectorXd lambda;  // the last successful step's (empty before one)
  const double energy_start = total_energy(particles, scene, lambda);
  const double scale = cl::energy_scale(particles, scene.gravity, scene.dt);
  const bool redundant = cl::lab07::hard_constraints_redundant(particles, scene.springs, map);

  // One step: the solve, then (--stabilize) the projection onto the hard
  // constraints; the loop's clock times both.
  double solve_seconds = 0.0, step_seconds = 0.0, stabilize_seconds = 0.0, projection_seconds = 0.0;
  double worst_error = 0.0, worst_before_projection = 0.0;
  auto step = [&](int) -> cl::StepVerdict {
    projection_seconds = 0.0;
    const cl::Timer step_timer;
    const cl::lab07::StepResult result = cl::lab07::constrained_step(particles, scene.springs, map, settings);
    solve_seconds = step_timer.seconds();
    step_seconds += solve_seconds;
    if (!result.ok) return {"singular: " + result.problem, false};
    lambda = result.lambda;
    if (lab.stabilize) {
      worst_before_projection =
          std::max(worst_before_projection, cl::lab07::max_constraint_error(particles.x, scene.springs));
      const cl::Timer projection_timer;
      const cl::lab07::ProjectionResult projection = cl::lab07::stabilize_positions(particles, scene.springs, map);
      projection_seconds = projection_timer.seconds();
      stabilize_seconds += projection_seconds;
      if (!projection.ok) return {"singular: " + projection.problem, false};
    }
    // Over every step taken, the one a run stops at included.
    worst_error = std::max(worst_error, cl::lab07::max_constraint_error(particles.x, scene.springs));
    return {};
  };
  auto measure = [&](int frame, double) {
    const double kinetic = cl::kinetic_energy(particles);
    const double potential = cl::potential_energy(particles, scene.gravity);
    const double elastic = spring_energy(particles.x, scene.springs, lambda);
    const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
    const double total = kinetic + potential + elastic;
    return cl::FrameMeasure{strain, total, {},
                            {cl::lab07::max_constraint_error(particles.x, scene.springs), strain.max, kinetic,
                             potential, elastic, total, frame > 0 ? solve_seconds : 0.0, projection_seconds},
                            {}};
  };
  const cl::FramePlan plan = cl::frame_plan(scene.steps, scene.dt, scale);
  cl::FrameOutput output = cl::frame_output(options, kLab, scene, "per_frame.csv",
                                            {"max_constraint_error", "max_strain", "kinetic", "potential",
                                             "spring_energy", "total_energy", "step_seconds", "stabilize_seconds"},
                                            options.method + (lab.stabilize ? ", stabilized" : ""));
  const cl::FrameLoopResult run = cl::run_frame_loop(particles, step, measure, plan, output);
  const int frames_done = run.frames_done;
  const int problem_frame = run.problem_frame;
  const std::string outcome = run.problem.empty() ? std::string() : run.status;  // "diverged: …" or "singular: …"

  const bool stopped = !outcome.empty();
  const double final_error = cl::lab07::max_constraint_error(particles.x, scene.springs);
  const cl::StrainStats strain = cl::strain_stats(particles.x, scene.springs);
  std::printf("%s: scene %s, %s, dt %.4g s, %d steps%s%s\n", kLab, describe_constraints(scene).c_str(),
              options.method.c_str(), scene.dt, scene.steps, lab.stabilize ? ", stabilized" : "",
              compliance_block ? "" : ", no compliance block (every constraint hard)");
  if (redundant) {
    std::printf("  the hard constraints are redundant at the start (J W J^T singular): lambda is not unique%s\n",
                lab.regularize > 0.0 ? " without the regularization" : "");
  }
  if (lab.regularize > 0.0) {
    std::printf("  regularized: every hard constraint has compliance %.3g m/N (a %.3g N/m spring)\n",
                lab.regularize, 1.0 / lab.regularize);
  }
  if (stopped) {
    cl::print_stopped("STOPPED", "step", problem_frame, scene.dt, outcome);
    if (outcome.rfind("singular", 0) == 0) {
      std::printf("  the state before that step is kept; --regularize EPS (e.g. 1e-9 m/N) makes every hard "
                  "constraint a stiff spring and the system solvable\n");
    }
  }
  if (!stopped || frames_done > 0) {
    std::printf("  max |phi| %.3e m at the end, %.3e m worst over the run%s; max strain %.3e\n", final_error,
                worst_error, lab.stabilize ? " (after projection)" : "", strain.max);
    if (lab.stabilize) std::printf("  worst max |phi| before the projection: %.3e m\n", worst_before_projection);
    const double energy = total_energy(particles, scene, lambda);
    std::printf("  energy: %.6e J (start %.6e J)\n", energy, energy_start);
  }
  const double steps_taken = std::max(1, frames_done);
  std::printf("  time %.3e s: %.3e s per step%s\n", run.seconds, run.seconds / steps_taken,
              lab.stabilize ? " (the solve and the projection)" : "");
  if (lab.stabilize) std::printf("  projection %.3e s per step (%.0f%% of the step)\n", stabilize_seconds / steps_taken,
                                 run.seconds > 0.0 ? 100.0 * stabilize_seconds / run.seconds : 0.0);
  cl::print_multipliers(lambda);

  cl::print_trajectory_note(options, "frame");
  if (!options.summary.empty()) {
    cl::RunSummary summary = cl::stepping_summary(kLab, options.method, scene, particles, strain, run.seconds);
    summary.extra["multipliers"] = std::vector<double>(lambda.data(), lambda.data() + lambda.size());
    summary.extra["max_constraint_error"] = final_error;
    summary.extra["worst_constraint_error"] = worst_error;
    summary.extra["stabilize"] = lab.stabilize;
    if (lab.stabilize) {
      summary.extra["worst_constraint_error_before_projection"] = worst_before_projection;
      summary.extra["stabilize_seconds"] = stabilize_seconds;
    }
    summary.extra["regularization"] = lab.regularize;
    summary.extra["redundant_at_start"] = redundant;
    summary.extra["compliance_block"] = compliance_block;
    summary.extra["steps_done"] = frames_done;
    summary.extra["step_seconds"] = step_seconds;
    cl::add_total_energy(summary, total_energy(particles, scene, lambda), energy_start);
    cl::add_stop_outcome(summary, outcome, "singular", problem_frame);
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

// ------------------------------------------------------------------ comparison

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

int run_compare(const cl::CommonOptions& options, const LabOptions& lab) {
  if (lab.stabilize) throw cl::InputError("--stabilize: not with a comparison");
  cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  apply_stiffness(scene, lab.stiffness);
  if (!options.out.empty()) cl::ensure_directory(options.out);
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
  for (const cl::lab07::Method method : {cl::lab07::Method::kSchur, cl::lab07::Method::kKkt}) {
    if (stabilized && method == cl::lab07::Method::kKkt) continue;
    for (const int n : substeps) {
      cl::lab07::StepSettings settings;
      settings.dt = scene.dt / n;
      settings.gravity = scene.gravity;
      settings.method = method;
      settings.regularization = lab.regularize;
      CompareRow row;
      row.method = method == cl::lab07::Method::kKkt ? "kkt" : (stabilized ? "schur-stabilized" : "schur");
      row.substeps = n;
      rows.push_back(measure(scene, row, [&](cl::Particles& particles, Eigen::VectorXd& lambda) {
        for (int s = 0; s < n; ++s) {
          cl::lab07::StepResult result = cl::lab07::constrained_step(particles, scene.springs, map, settings);
          if (!result.ok) return result.problem;
          lambda = std::move(result.lambda);
          if (stabilized) {
            const cl::lab07::ProjectionResult projection =
                cl::lab07::stabilize_positions(particles, scene.springs, map);
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
  std::printf("%s: scene %s, %d frames of %.4g s; strain = max over springs of |phi|/L after each frame\n", kLab,
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

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  if (lab.compare_pbd.empty() && lab.compare_substeps.empty()) return run_one(options, lab);
  cl::refuse_run_flags(options, "only for one run (not with --compare-pbd or --compare-substeps)",
                       "a comparison writes compare.csv, not a run summary");
  return run_compare(options, lab);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Lab 07: constrained dynamics. Implicit Euler with linearised distance constraints, solved as one "
               "KKT system or by its Schur complement; writes per-frame constraint error and energy and a summary "
               "with the multipliers. Or compares PBD (lab 04) with both solves on one scene.",
               CL_PROGRAM_NAME};
  cl::CommonOptions options = cl::lab_defaults("ragdoll-chain-20", "schur", {"kkt", "schur"});
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagMethod | cl::kFlagDt | cl::kFlagSteps | cl::kFlagOut |
                             cl::kFlagSummary | cl::kFlagFrames);
  LabOptions lab;
  app.add_flag("--stabilize", lab.stabilize,
               "after every step, project the positions once onto the hard constraints (velocities unchanged)");
  app.add_option("--regularize", lab.regularize,
                 "compliance (m/N) added to every hard constraint, e.g. 1e-9: a way out of a singular system")
      ->check(cl::finite_number(true));
  app.add_option("--stiffness", lab.stiffness, "replace every spring's stiffness: a number (N/m) or inf");
  app.add_option("--compare-pbd", lab.compare_pbd,
                 "compare: PBD (lab 04, Gauss-Seidel) with these iteration counts, one substep; writes compare.csv")
      ->delimiter(',')
      ->check(CLI::Range(1, 1'000'000));
  app.add_option("--compare-substeps", lab.compare_substeps,
                 "compare: the KKT and Schur steps (and PBD with one iteration) at these substeps per frame")
      ->delimiter(',')
      ->check(CLI::Range(1, 1'000'000));
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
