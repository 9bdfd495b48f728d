// lab03_jacobi: K Jacobi sweeps over a scene's springs (or, with --method
// gauss-seidel, lab 02's sweeps in file order, for the side-by-side
// comparison), with the strain error, the change in positions and the wall
// time of every sweep. Divergence (ω ≥ 2) is a reported outcome, not a failure.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <utility>

#include "common/cli.h"
#include "common/driver.h"
#include "common/openmp.h"
#include "common/output.h"
#include "common/summary.h"
#include "common/timer.h"
#include "common/trajectory.h"
#include "gauss_seidel.h"
#include "jacobi.h"
#include "sweep_log.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;

struct LabOptions {
  double omega = 1.0;
  int threads = 1;
  std::string averaging = "count";
  double tolerance = 1e-10;
};

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle), values.end());
  return values[middle];
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  const cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  // Without a spring every sweep is empty: "converged" would say nothing.
  if (scene.springs.empty()) throw cl::InputError(scene.source + ": no springs: a sweep has nothing to project");
  const bool jacobi = options.method == "jacobi";
  if (cl::check_mode()) {  // a sweep lab: sweeps, not time steps, and what shapes them
    std::string line = ", " + std::to_string(options.iterations) + " sweeps, --method " + options.method;
    if (jacobi) line += ", --omega " + cl::format_double(lab.omega) + ", --averaging " + lab.averaging;
    if (!options.out.empty()) line += ", writes " + options.out + "/";
    if (!options.summary.empty()) line += ", summary " + options.summary;
    throw cl::CheckStop{line};
  }
  cl::start_run(options);
  const cl::lab03::Averaging averaging =
      lab.averaging == "none" ? cl::lab03::Averaging::kNone : cl::lab03::Averaging::kByCount;
  const Eigen::VectorXd& inv_mass = scene.particles.inv_mass;
  const std::size_t spring_count = scene.springs.size();

  std::printf("%s: scene %s, %ld particles, %zu springs, %d ", kLab, scene.name.c_str(),
              static_cast<long>(scene.particles.size()), spring_count, options.iterations);
  if (jacobi) {
    cl::set_openmp_threads(lab.threads);
    std::printf("Jacobi sweeps (omega %g, %s, %d thread%s)\n", lab.omega,
                averaging == cl::lab03::Averaging::kByCount ? "averaged by count" : "summed, no averaging",
                lab.threads, lab.threads == 1 ? "" : "s");
  } else {
    std::printf("Gauss-Seidel sweeps in file order\n");
  }

  const cl::lab03::Incidence incidence = cl::lab03::build_incidence(scene.particles.size(), scene.springs);
  std::vector<int> order(spring_count);
  std::iota(order.begin(), order.end(), 0);

  cl::lab02::ConvergenceLog log(scene.springs, lab.tolerance);
  Eigen::Matrix3Xd x = scene.particles.x;
  Eigen::Matrix3Xd other = x;  // Jacobi: x_next; Gauss-Seidel: the state before the sweep
  log.start(x);
  // One frame per due sweep (and the last, and one that diverged) for ./course view.
  std::optional<cl::TrajectoryWriter> trajectory;
  if (options.frames > 0) {
    const std::string method = jacobi ? "jacobi, omega " + cl::format_double(lab.omega) : "gauss-seidel";
    trajectory.emplace(options.out, options.frames, scene, cl::TrajectoryIdentity{kLab, method, "", "sweep"});
    trajectory->add(0, 0.0, x, std::numeric_limits<double>::quiet_NaN(), "ok");
  }
  auto keep = [&](int sweep, const Eigen::Matrix3Xd& state, bool finite) {
    if (trajectory && (!finite || trajectory->due(sweep) || sweep == options.iterations)) {
      trajectory->add(sweep, sweep, state, std::numeric_limits<double>::quiet_NaN(), finite ? "ok" : "diverged");
    }
  };
  for (int sweep = 1; sweep <= options.iterations; ++sweep) {
    if (jacobi) {
      const cl::Timer timer;
      cl::lab03::jacobi_sweep(x, other, inv_mass, scene.springs, incidence, lab.omega, averaging);
      const double seconds = timer.seconds();
      const bool finite = log.record(x, other, seconds);
      keep(sweep, other, finite);
      if (!finite) break;  // x stays the last finite state
      std::swap(x, other);
    } else {
      other = x;
      const cl::Timer timer;
      cl::lab02::gauss_seidel_sweep(x, inv_mass, scene.springs, order);
      const double seconds = timer.seconds();
      const bool finite = log.record(other, x, seconds);
      keep(sweep, x, finite);
      if (!finite) {
        x = other;
        break;
      }
    }
  }

  std::printf("%s  %s\n", cl::lab02::format_log(log).c_str(), cl::lab02::format_outcome(log).c_str());
  std::vector<double> sweep_seconds;
  for (const cl::lab02::SweepRecord& record : log.records()) {
    if (record.sweep > 0) sweep_seconds.push_back(record.sweep_seconds);
  }
  const double median_seconds = median(sweep_seconds);
  // Jacobi projects each spring once from each end (the gather); Gauss-Seidel once.
  const double projections = static_cast<double>(spring_count) * (jacobi ? 2.0 : 1.0);
  const double seconds = log.last().total_seconds;
  std::printf("  time %.3e s; per sweep: median %.3e s, %.3g projections per second\n", seconds, median_seconds,
              median_seconds > 0.0 ? projections / median_seconds : 0.0);

  if (!options.out.empty()) log.table().write(cl::join_path(options.out, "convergence.csv"));
  if (trajectory) trajectory->finish();
  cl::print_trajectory_note(options, "sweep");
  if (!options.summary.empty()) {
    cl::RunSummary summary;
    summary.lab = kLab;
    summary.method = options.method;
    summary.scene = scene.name;
    summary.iterations = options.iterations;
    summary.positions = x;
    summary.max_strain_error = log.last().max_strain_error;
    summary.seconds = seconds;
    if (jacobi) {
      summary.extra["omega"] = lab.omega;
      summary.extra["averaging"] = lab.averaging;
      summary.extra["threads"] = lab.threads;
    } else {
      summary.extra["order"] = "forward";
    }
    summary.extra["springs"] = spring_count;
    summary.extra["projections_per_sweep"] = projections;
    summary.extra["median_sweep_seconds"] = median_seconds;
    summary.extra["rms_strain_error"] = log.last().rms_strain_error;
    summary.extra["max_strain_error_before"] = log.records().front().max_strain_error;
    const nlohmann::ordered_json outcome = cl::lab02::outcome_json(log);
    for (const auto& item : outcome.items()) summary.extra[item.key()] = item.value();
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 03: Jacobi sweeps (or Gauss-Seidel, for comparison) over a scene's springs; strain error, "
      "position change and wall time per sweep.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options;
  options.scene = "chain-20";
  options.iterations = 100;
  options.method = "jacobi";
  options.methods = {"jacobi", "gauss-seidel"};
  options.frames_are_sweeps = true;
  options.steps = 0;  // no time steps: the scene's dt and steps are not read
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagMethod | cl::kFlagIterations | cl::kFlagOut | cl::kFlagSummary |
                             cl::kFlagFrames);
  app.get_option("--iterations").description("sweeps over all springs (this lab has no time steps)");
  LabOptions lab;
  lab.threads = cl::openmp_max_threads();
  // Only the Jacobi sweep reads these: with --method gauss-seidel they are refused, not ignored.
  app.add_option("--omega", lab.omega, "Jacobi relaxation factor (0 leaves x unchanged; 0 < omega < 2 converges)")
      .non_negative()
      .capture_default_str()
      .only_for_methods({"jacobi"});
  app.add_option("--threads", lab.threads, "OpenMP threads for the Jacobi sweep")
      .range(1, 1024)
      .capture_default_str()
      .only_for_methods({"jacobi"});
  app.add_option("--averaging", lab.averaging,
                 "count: divide each particle's summed correction by its spring count; none: plain summed Jacobi")
      .one_of({"count", "none"})
      .capture_default_str()
      .only_for_methods({"jacobi"});
  app.add_option("--tolerance", lab.tolerance, "max strain error that counts as converged")
      .positive()
      .capture_default_str();
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
