// Lab 13 — given code: the stiffness override and the convergence experiment.
#include "experiments.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "../lab06_projective_dynamics/experiments.h"
#include "../lab06_projective_dynamics/simulation.h"
#include "common/csv.h"
#include "common/driver.h"
#include "common/output.h"
#include "common/timer.h"

namespace cl::lab13 {

double parse_stiffness(const std::string& flag, const std::string& text) {
  if (text == "inf") return std::numeric_limits<double>::infinity();
  std::size_t used = 0;
  double k = 0.0;
  try {
    k = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  // Decimal only: std::stod also reads hexadecimal ("0x10" would be 16 N/m).
  if (text.find_first_not_of("0123456789.eE+-") != std::string::npos) used = 0;
  if (used != text.size() || !std::isfinite(k) || !(k > 0.0)) {
    throw InputError(flag + ": '" + text + "' is not a stiffness (a finite number > 0 in N/m, or inf)");
  }
  return k;
}

void set_stiffness(Scene& scene, double k) {
  for (Spring& spring : scene.springs) spring.stiffness = k;
}

namespace {

constexpr double kTargets[] = {1e-2, 1e-3, 1e-6};  // relative distances to x*

// A list flag's names, each converted by from_name; a refusal names the flag.
template <typename T>
std::vector<T> from_names(const std::string& flag, const std::vector<std::string>& names,
                          T (*from_name)(const std::string&)) {
  std::vector<T> values;
  for (const std::string& name : names) {
    try {
      values.push_back(from_name(name));
    } catch (const std::invalid_argument& error) {
      throw InputError(flag + ": " + error.what());
    }
  }
  return values;
}

// rms_p ‖a_p − b_p‖ over the movable particles.
double rms_difference(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b, const MovableMap& map) {
  if (map.unknowns() == 0) return 0.0;
  double sum = 0.0;
  for (const int p : map.particle_of) sum += (a.col(p) - b.col(p)).squaredNorm();
  return std::sqrt(sum / map.unknowns());
}

// One method's run towards x*: the distance after every iteration.
struct Curve {
  std::string method, start, warm;
  std::vector<int> iterations;
  std::vector<double> seconds, distances, force_errors;
  int backtracks = 0;
  std::string problem;
};

}  // namespace

int run_convergence(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                    const LabOptions& lab) {
  refuse_run_flags(options, "--convergence writes CSV files, not a trajectory",
                   "--convergence writes CSV files, not a run summary");
  std::vector<double> stiffnesses;
  for (const std::string& text : lab.stiffnesses) stiffnesses.push_back(parse_stiffness("--stiffnesses", text));
  const std::vector<Start> starts = from_names("--starts", lab.starts, start_from_name);
  const std::vector<Warm> warms = from_names("--warms", lab.warms, warm_from_name);
  const std::vector<Scene> scenes = load_scenes(options, lab.sweep_scenes, scene_dir);
  start_run(options);

  CsvTable curves({"scene", "stiffness", "method", "start", "warm", "iteration", "seconds", "distance",
                   "force_error"});
  CsvTable crossover({"scene", "stiffness", "method", "start", "warm", "iterations_1e-2", "seconds_1e-2",
                      "iterations_1e-3", "seconds_1e-3", "iterations_1e-6", "seconds_1e-6", "final_distance",
                      "backtracks", "reference_force_error", "reference_gradient", "problem"});
  std::printf("%s: one step to its converged result x*, after %d constrained Newton steps; iterations (seconds) "
              "to a relative distance of 1e-2, 1e-3, 1e-6 of x*\n",
              lab_name, lab.warmup);
  for (const Scene& base : scenes) {
    for (const double k : stiffnesses) {
      Scene scene = base;
      set_stiffness(scene, k);
      Particles start = scene.particles;
      Solver warm_solver(start.inv_mass, scene.springs, scene.dt);
      Settings warmup = lab.settings;
      warmup.gravity = scene.gravity;
      warmup.iterations = 50;
      warmup.tolerance = 1e-10;
      // The start and x* are the exact iteration's whatever --compression
      // says, so that drop's rows are measured against the same converged x*
      // as keep's (drop's own stops short of round-off, its slow tail).
      warmup.compression = lab09::Compression::kKeep;
      std::string problem;
      for (int s = 0; s < lab.warmup && problem.empty(); ++s) problem = warm_solver.step(start, warmup).problem;
      const std::string k_text = format_double(k);
      if (!problem.empty()) {
        std::printf("%-16s k %-6s warm-up failed: %s\n", scene.name.c_str(), k_text.c_str(), problem.c_str());
        continue;
      }
      const Eigen::Matrix3Xd y = lab06::predict(start, scene.gravity, scene.dt);
      const MovableMap& map = warm_solver.map();
      // x*: constrained Newton to round-off (the merit stops falling there).
      Settings exact = warmup;
      exact.iterations = 60;
      exact.tolerance = 0.0;
      exact.start = Start::kPositions;
      exact.warm = Warm::kForces;
      Eigen::Matrix3Xd best = start.x;
      Eigen::VectorXd best_lambda = warm_start(start.x, warm_solver.springs(), warm_solver.previous_lambda(), Warm::kForces);
      const StepReport reference = warm_solver.iterate(best, best_lambda, y, exact);
      if (!reference.problem.empty()) {
        std::printf("%-16s k %-6s reference failed: %s\n", scene.name.c_str(), k_text.c_str(),
                    reference.problem.c_str());
        continue;
      }
      const bool finite = std::isfinite(k);
      const lab06::Problem problem_k = finite ? lab06::problem_of(scene) : lab06::Problem{};
      const double gradient =
          finite ? lab06::newton_gradient(problem_k, best, y).cwiseAbs().maxCoeff() : std::nan("");
      const double displacement = rms_difference(best, start.x, map);
      auto distance = [&](const Eigen::Matrix3Xd& x) {
        return displacement > 0.0 ? rms_difference(x, best, map) / displacement : rms_difference(x, best, map);
      };

      std::vector<Curve> runs;
      for (const Start s : starts) {
        for (const Warm w : warms) {
          Curve curve{"constrained-newton", start_name(s), warm_name(w), {}, {}, {}, {}, 0, {}};
          Settings settings = warmup;
          settings.iterations = lab.newton_cap;
          settings.tolerance = 0.0;
          settings.start = s;
          Eigen::Matrix3Xd x = s == Start::kPrediction ? y : start.x;
          Eigen::VectorXd lambda = warm_start(start.x, warm_solver.springs(), warm_solver.previous_lambda(), w);
          const StepReport report = warm_solver.iterate(x, lambda, y, settings, [&](const IterationRecord& r) {
            const double d = distance(*r.x);
            curve.iterations.push_back(r.iteration);
            curve.seconds.push_back(r.seconds);
            curve.distances.push_back(d);
            curve.force_errors.push_back(r.force_error);
            return d <= kTargets[2] || r.seconds > lab.max_seconds;
          });
          curve.backtracks = report.backtracks;
          curve.problem = report.problem;
          if (report.failed_decreases > 0) {
            curve.problem = "no decrease of the merit after iteration " + std::to_string(report.iterations_done);
          }
          runs.push_back(std::move(curve));
        }
      }
      if (finite) {
        for (const lab06::Method method : {lab06::Method::kNewton, lab06::Method::kProjectiveDynamics}) {
          Curve curve{lab06::method_name(method), "prediction", "-", {}, {}, {}, {}, 0, {}};
          lab06::Solver solver(problem_k, method);
          lab06::StepSettings settings;
          settings.gravity = scene.gravity;
          settings.iterations = method == lab06::Method::kNewton ? lab.newton_cap : lab.pd_cap;
          Particles copy = start;
          const lab06::StepReport report = solver.step(copy, settings, [&](const lab06::IterationRecord& r) {
            const double d = distance(*r.x);
            curve.iterations.push_back(r.iteration);
            curve.seconds.push_back(r.seconds);
            curve.distances.push_back(d);
            curve.force_errors.push_back(std::nan(""));
            return d <= kTargets[2] || r.seconds > lab.max_seconds;
          });
          curve.problem = report.problem.empty() ? solver.setup_problem() : report.problem;
          runs.push_back(std::move(curve));
        }
      }
      for (const Curve& curve : runs) {
        std::vector<CsvCell> row{scene.name, k, curve.method, curve.start, curve.warm};
        std::printf("%-16s k %-6s %-18s %-10s %-6s", scene.name.c_str(), k_text.c_str(), curve.method.c_str(),
                    curve.start.c_str(), curve.warm.c_str());
        for (const double target : kTargets) {
          std::size_t i = 0;
          while (i < curve.distances.size() && !(curve.distances[i] <= target)) ++i;
          const bool reached = i < curve.distances.size();
          row.push_back(reached ? CsvCell{static_cast<long long>(curve.iterations[i])} : CsvCell{std::string()});
          row.push_back(cell_if(reached, reached ? curve.seconds[i] : 0.0));
          if (reached) {
            std::printf("  %5d (%8.3g s)", curve.iterations[i], curve.seconds[i]);
          } else {
            std::printf("  %5s %12s", "-", "");
          }
        }
        const double last = curve.distances.empty() ? std::nan("") : curve.distances.back();
        row.push_back(last);
        row.push_back(static_cast<long long>(curve.backtracks));
        row.push_back(reference.force_error);
        row.push_back(cell_if(finite, gradient));
        row.push_back(curve.problem);
        crossover.add_row(row);
        std::printf("  last %.2e%s%s\n", last, curve.problem.empty() ? "" : "; ", curve.problem.c_str());
        for (std::size_t i = 0; i < curve.distances.size(); ++i) {
          curves.add_row({scene.name, k, curve.method, curve.start, curve.warm,
                          static_cast<long long>(curve.iterations[i]), curve.seconds[i], curve.distances[i],
                          cell_if(std::isfinite(curve.force_errors[i]), curve.force_errors[i])});
        }
      }
      std::printf("%-16s k %-6s x*: force error %.1e after %d iterations%s", scene.name.c_str(), k_text.c_str(),
                  reference.force_error, reference.iterations_done, finite ? "" : "\n");
      if (finite) std::printf(", |grad g| %.1e N (lab 06's gradient)\n", gradient);
      std::fflush(stdout);
    }
  }
  if (!options.out.empty()) {
    curves.write(join_path(options.out, "convergence.csv"));
    crossover.write(join_path(options.out, "crossover.csv"));
  }
  return 0;
}

}  // namespace cl::lab13
