#include "experiments.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "common/csv.h"
#include "common/driver.h"
#include "common/output.h"

namespace cl::lab06 {

namespace {

// --stiffness applied to `scene`, and its hard constraints refused.
void make_finite(const char* lab_name, const LabOptions& lab, Scene& scene) {
  for (std::size_t e = 0; e < scene.springs.size(); ++e) {
    cl::Spring& spring = scene.springs[e];
    if (lab.stiffness) spring.stiffness = *lab.stiffness;
    if (std::isinf(spring.stiffness)) {
      throw cl::InputError(scene.source + ": springs[" + std::to_string(e) + "] (particles " +
                           std::to_string(spring.i) + "-" + std::to_string(spring.j) +
                           ").stiffness: inf is a hard constraint; " + lab_name +
                           " needs finite springs (lab 07 handles hard constraints), or pass --stiffness");
    }
  }
}

}  // namespace

Scene load_finite_scene(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                        const LabOptions& lab, const std::string& name) {
  cl::CommonOptions one = options;
  one.scene = name;
  cl::Scene scene = cl::load_scene_for(one, scene_dir);
  make_finite(lab_name, lab, scene);
  return scene;
}

Problem problem_of(const Scene& scene) {
  return make_problem(scene.particles.inv_mass, scene.springs, scene.dt);
}

namespace {

constexpr double kTargets[] = {1e-2, 1e-3, 1e-6};  // relative objective errors (g − g*)/g*

struct Curve {
  std::string method;
  std::vector<IterationRecord> records;
  double setup_seconds = 0.0;  // PD: the factorization, once per scene
  std::string problem;
  int failed_decreases = 0;
  bool converged = false;
  bool timed_out = false;
};

// One step of `method` from `start`, recording every iterate. Stops at `cap`
// iterations, after max_seconds of wall time (if > 0, setup included), or
// once (g − best_known)/best_known <= stop_gap, if best_known (a previous
// run's minimum) is finite.
Curve measure_step(Solver& solver, const cl::Particles& start, const StepSettings& base,
                   int cap, double best_known, double stop_gap, double max_seconds) {
  Curve curve;
  curve.method = method_name(solver.method());
  curve.setup_seconds = solver.method() == Method::kProjectiveDynamics ? solver.factor_seconds() : 0.0;
  StepSettings settings = base;
  settings.iterations = cap;
  // Newton stops once the objective stops moving (at round-off); PD runs to
  // its cap or to stop_gap.
  settings.tolerance = solver.method() == Method::kNewton ? 1e-15 : 0.0;
  cl::Particles particles = start;
  const StepReport report =
      solver.step(particles, settings, [&](const IterationRecord& record) {
        curve.records.push_back(record);
        if (max_seconds > 0.0 && record.seconds + curve.setup_seconds >= max_seconds) {
          curve.timed_out = true;
          return true;
        }
        return std::isfinite(best_known) && record.objective - best_known <= stop_gap * std::abs(best_known);
      });
  curve.problem = report.problem;
  curve.failed_decreases = report.failed_decreases;
  curve.converged = report.converged;
  return curve;
}

}  // namespace

int run_convergence(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                    const LabOptions& lab) {
  std::vector<cl::Scene> scenes = cl::load_scenes(options, lab.sweep_scenes, scene_dir);
  for (cl::Scene& scene : scenes) make_finite(lab_name, lab, scene);
  cl::start_run(options);
  cl::CsvTable curves({"scene", "particles", "unknowns", "springs", "method", "iteration", "objective", "gap",
                       "relative_error", "seconds", "setup_seconds", "factorizations", "reference_converged",
                       "reference_last_decrease"});
  cl::CsvTable crossover({"scene", "particles", "unknowns", "method", "target", "reached", "iterations",
                          "seconds", "seconds_without_setup", "factorizations", "setup_seconds"});
  std::printf("%s: one step of each scene to its minimum (after %d warm-up step(s) of PD with K = %d); caps: "
              "PD %d, Newton %d iterations\n",
              lab_name, lab.warmup, options.iterations, lab.pd_cap, lab.newton_cap);
  std::printf("%-16s %8s %-7s %9s  %-22s %-22s %-22s %10s %8s  %s\n", "scene", "unknowns", "method", "setup/s",
              "1e-2: its, seconds", "1e-3: its, seconds", "1e-6: its, seconds", "factorized", "total/s", "note");
  for (const cl::Scene& scene : scenes) {
    Solver pd(problem_of(scene), Method::kProjectiveDynamics);
    Solver newton(problem_of(scene), Method::kNewton);
    StepSettings settings;
    settings.gravity = scene.gravity;
    settings.iterations = options.iterations;
    cl::Particles start = scene.particles;
    for (int w = 0; w < lab.warmup; ++w) {
      const StepReport report = pd.step(start, settings);
      if (!report.problem.empty()) {
        throw cl::InputError(scene.source + ": warm-up step " + std::to_string(w + 1) + " failed: " + report.problem);
      }
    }
    // Newton first, to round-off (or its cap): its end is the reference
    // minimum, and the PD run stops once within --stop-gap of it.
    const Curve newton_curve = measure_step(newton, start, settings, lab.newton_cap,
                                            std::numeric_limits<double>::quiet_NaN(), lab.stop_gap, lab.max_seconds);
    double best = std::numeric_limits<double>::infinity();
    for (const auto& record : newton_curve.records) best = std::min(best, record.objective);
    // How far the reference may still be from the minimum: Newton's last
    // decrease, relative (0 when it converged to round-off).
    const std::size_t count = newton_curve.records.size();
    const bool reference_converged =
        newton_curve.problem.empty() && newton_curve.failed_decreases == 0 && newton_curve.converged;
    const double reference_last_decrease =
        reference_converged || count < 2
            ? 0.0
            : (newton_curve.records[count - 2].objective - newton_curve.records[count - 1].objective) /
                  std::abs(newton_curve.records[count - 1].objective);
    const Curve pd_curve = measure_step(pd, start, settings, lab.pd_cap, best, lab.stop_gap, lab.max_seconds);
    for (const auto& record : pd_curve.records) best = std::min(best, record.objective);

    const auto unknowns = static_cast<long long>(pd.problem().map.unknowns());
    for (const Curve* curve : {&pd_curve, &newton_curve}) {
      std::vector<int> reached_at(std::size(kTargets), -1);
      for (std::size_t r = 0; r < curve->records.size(); ++r) {
        const auto& record = curve->records[r];
        const double gap = record.objective - best;
        const double relative = best != 0.0 ? gap / std::abs(best) : gap;
        curves.add_row({scene.name, static_cast<long long>(scene.particles.size()), unknowns,
                        static_cast<long long>(scene.springs.size()), curve->method,
                        static_cast<long long>(record.iteration), record.objective, gap, relative,
                        record.seconds + curve->setup_seconds, curve->setup_seconds,
                        static_cast<long long>(record.factorizations),
                        static_cast<long long>(reference_converged ? 1 : 0), reference_last_decrease});
        for (std::size_t t = 0; t < std::size(kTargets); ++t) {
          if (reached_at[t] < 0 && relative <= kTargets[t]) reached_at[t] = static_cast<int>(r);
        }
      }
      std::string cells[std::size(kTargets)];
      for (std::size_t t = 0; t < std::size(kTargets); ++t) {
        // A target near the reference's own uncertainty cannot be judged.
        const bool decidable = reference_converged || kTargets[t] > 10.0 * reference_last_decrease;
        const bool reached = decidable && reached_at[t] >= 0;
        const IterationRecord none;
        const auto& record = reached ? curve->records[static_cast<std::size_t>(reached_at[t])] : none;
        crossover.add_row({scene.name, static_cast<long long>(scene.particles.size()), unknowns, curve->method,
                           kTargets[t], std::string(!decidable ? "undecided" : reached ? "yes" : "no"),
                           static_cast<long long>(record.iteration), record.seconds + curve->setup_seconds,
                           record.seconds, static_cast<long long>(record.factorizations), curve->setup_seconds});
        char cell[48];
        std::snprintf(cell, sizeof cell, "%6d %9.3g", record.iteration, record.seconds + curve->setup_seconds);
        cells[t] = reached ? cell : decidable ? "     -         -" : "     ?         ?";
      }
      const double total = curve->records.empty() ? 0.0 : curve->records.back().seconds + curve->setup_seconds;
      std::string note = curve->problem;
      if (curve->failed_decreases > 0) note += "a line search found no decrease";
      if (note.empty() && curve->timed_out) note = "stopped at --max-seconds";
      if (note.empty() && curve == &pd_curve && !curve->records.empty() &&
          curve->records.back().iteration == lab.pd_cap) {
        note = "stopped at the cap";
      }
      if (curve == &newton_curve && !reference_converged) {
        char text[96];
        std::snprintf(text, sizeof text, "%sreference: last decrease %.1e", note.empty() ? "" : "; ",
                      reference_last_decrease);
        note += text;
      }
      std::printf("%-16s %8lld %-7s %9.3g  %-22s %-22s %-22s %10d %8.3g  %s\n", scene.name.c_str(), unknowns,
                  curve->method.c_str(), curve->setup_seconds, cells[0].c_str(), cells[1].c_str(), cells[2].c_str(),
                  curve->records.empty() ? 0 : curve->records.back().factorizations, total, note.c_str());
    }
    std::fflush(stdout);
  }
  if (!options.out.empty()) {
    curves.write(cl::join_path(options.out, "convergence.csv"));
    crossover.write(cl::join_path(options.out, "crossover.csv"));
  }
  return 0;
}

}  // namespace cl::lab06
