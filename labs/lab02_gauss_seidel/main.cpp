// lab02_gauss_seidel: K Gauss-Seidel sweeps over a scene's springs in a chosen
// order, with the strain error and the change in positions after every sweep.
// With --compare ORDER: the same sweeps from the same start in a second order,
// and how far apart the two final states are.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/driver.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "common/timer.h"
#include "common/trajectory.h"
#include "gauss_seidel.h"
#include "sweep_log.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;

struct LabOptions {
  std::string order = "forward";
  std::string compare;  // empty: no second order
  long long seed = 1;
  double tolerance = 1e-10;
};

// The median wall time of one sweep in the log (NaN when it has none).
double median_sweep_seconds(const cl::lab02::ConvergenceLog& log) {
  std::vector<double> seconds;
  for (const cl::lab02::SweepRecord& record : log.records()) {
    if (record.sweep > 0) seconds.push_back(record.sweep_seconds);
  }
  if (seconds.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(seconds.begin(), seconds.begin() + static_cast<std::ptrdiff_t>(seconds.size() / 2), seconds.end());
  return seconds[seconds.size() / 2];
}

// K sweeps in `order` from `start`; returns the log, leaves the final state in x
// and keeps the state after every due sweep in `trajectory` (when given).
cl::lab02::ConvergenceLog run_sweeps(const cl::Scene& scene, const Eigen::Matrix3Xd& start, int iterations,
                                     cl::lab02::Order order, const LabOptions& lab, Eigen::Matrix3Xd& x,
                                     cl::TrajectoryWriter* trajectory = nullptr) {
  const double no_energy = std::numeric_limits<double>::quiet_NaN();
  cl::lab02::ConvergenceLog log(scene.springs, lab.tolerance);
  cl::lab02::SweepOrder orders(scene.springs.size(), order, static_cast<std::uint64_t>(lab.seed));
  x = start;
  log.start(x);
  if (trajectory) trajectory->add(0, 0.0, x, no_energy, "ok");
  Eigen::Matrix3Xd before;
  for (int sweep = 1; sweep <= iterations; ++sweep) {
    before = x;
    const std::vector<int>& sweep_order = orders.next();
    const cl::Timer timer;
    cl::lab02::gauss_seidel_sweep(x, scene.particles.inv_mass, scene.springs, sweep_order);
    const double seconds = timer.seconds();
    const bool finite = log.record(before, x, seconds);
    if (trajectory && (!finite || trajectory->due(sweep) || sweep == iterations)) {
      trajectory->add(sweep, sweep, x, no_energy, finite ? "ok" : "diverged");
    }
    if (!finite) {
      x = before;  // the last finite state is the one reported
      break;
    }
  }
  return log;
}

void write_positions(const std::string& path, const Eigen::VectorXd& inv_mass, const Eigen::Matrix3Xd& start,
                     const Eigen::Matrix3Xd& final_state, const Eigen::Matrix3Xd* compared) {
  std::vector<std::string> columns{"particle", "inv_mass", "x0", "y0", "z0", "x", "y", "z"};
  if (compared) columns.insert(columns.end(), {"x_compare", "y_compare", "z_compare"});
  cl::CsvTable table(columns);
  for (Eigen::Index p = 0; p < start.cols(); ++p) {
    std::vector<cl::CsvCell> row{static_cast<long long>(p), inv_mass[p], start(0, p), start(1, p), start(2, p),
                                 final_state(0, p), final_state(1, p), final_state(2, p)};
    if (compared) row.insert(row.end(), {(*compared)(0, p), (*compared)(1, p), (*compared)(2, p)});
    table.add_row(row);
  }
  table.write(path);
}

int run(const cl::CommonOptions& options, const LabOptions& lab) {
  const cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  cl::start_run(options);
  const cl::lab02::Order order = cl::lab02::order_from_name(lab.order);
  const Eigen::Matrix3Xd start = scene.particles.x;

  std::printf("%s: scene %s, %ld particles, %zu springs, %d Gauss-Seidel sweeps in %s order", kLab,
              scene.name.c_str(), static_cast<long>(start.cols()), scene.springs.size(), options.iterations,
              lab.order.c_str());
  if (order == cl::lab02::Order::kRandom) std::printf(" (seed %lld)", lab.seed);
  std::printf("\n");

  Eigen::Matrix3Xd x;
  std::optional<cl::TrajectoryWriter> trajectory;
  if (options.frames > 0) {
    trajectory.emplace(options.out, options.frames, scene,
                       cl::TrajectoryIdentity{kLab, "gauss-seidel, " + lab.order + " order", "", "sweep"});
  }
  const cl::lab02::ConvergenceLog log =
      run_sweeps(scene, start, options.iterations, order, lab, x, trajectory ? &*trajectory : nullptr);
  std::printf("%s  %s\n", cl::lab02::format_log(log).c_str(), cl::lab02::format_outcome(log).c_str());
  const double seconds = log.last().total_seconds;
  const int sweeps = log.last().sweep;
  std::printf("  time %.3e s (%.3e s per sweep, %.3e s per projection)\n", seconds,
              sweeps > 0 ? seconds / sweeps : 0.0,
              sweeps > 0 && !scene.springs.empty() ? seconds / sweeps / static_cast<double>(scene.springs.size())
                                                   : 0.0);

  nlohmann::ordered_json compare_json;
  Eigen::Matrix3Xd x_compare;
  if (!lab.compare.empty()) {
    const cl::lab02::Order other = cl::lab02::order_from_name(lab.compare);
    const cl::lab02::ConvergenceLog other_log = run_sweeps(scene, start, options.iterations, other, lab, x_compare);
    const double difference = cl::lab02::max_distance(x, x_compare);
    std::printf("  %s vs %s after %d sweeps: final states differ by up to %.3e m; max strain errors %.3e and %.3e"
                " (%s)\n",
                lab.order.c_str(), lab.compare.c_str(), options.iterations, difference, log.last().max_strain_error,
                other_log.last().max_strain_error, cl::lab02::outcome_name(other_log.outcome()));
    // The same projections in another order: what the order alone does to the
    // time (the median sweep of each run, robust to another job's turn).
    const double ratio = median_sweep_seconds(other_log) / median_sweep_seconds(log);
    if (std::isfinite(ratio) && ratio > 0.0) {
      std::printf("  median sweep time, %s / %s: %.2f\n", lab.compare.c_str(), lab.order.c_str(), ratio);
    }
    compare_json["order"] = lab.compare;
    compare_json["max_position_difference"] = difference;
    compare_json["max_strain_error"] = other_log.last().max_strain_error;
    compare_json["outcome"] = cl::lab02::outcome_name(other_log.outcome());
    compare_json["positions"] = nlohmann::ordered_json::array();
    for (Eigen::Index p = 0; p < x_compare.cols(); ++p) {
      compare_json["positions"].push_back({x_compare(0, p), x_compare(1, p), x_compare(2, p)});
    }
  }

  if (!options.out.empty()) {
    log.table().write(cl::join_path(options.out, "convergence.csv"));
    write_positions(cl::join_path(options.out, "positions.csv"), scene.particles.inv_mass, start, x,
                    lab.compare.empty() ? nullptr : &x_compare);
  }
  if (trajectory) trajectory->finish();
  cl::print_trajectory_note(options, "sweep");
  if (!options.summary.empty()) {
    cl::RunSummary summary;
    summary.lab = kLab;
    summary.method = "gauss-seidel";
    summary.scene = scene.name;
    summary.iterations = options.iterations;
    summary.positions = x;
    summary.max_strain_error = log.last().max_strain_error;
    summary.seconds = seconds;
    summary.extra["order"] = lab.order;
    if (order == cl::lab02::Order::kRandom) summary.extra["seed"] = lab.seed;
    summary.extra["springs"] = scene.springs.size();
    summary.extra["rms_strain_error"] = log.last().rms_strain_error;
    summary.extra["max_strain_error_before"] = log.records().front().max_strain_error;
    const nlohmann::ordered_json outcome = cl::lab02::outcome_json(log);
    for (const auto& item : outcome.items()) summary.extra[item.key()] = item.value();
    if (!lab.compare.empty()) summary.extra["compare"] = compare_json;
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 02: Gauss-Seidel sweeps over a scene's springs; strain error and position change per sweep.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options;
  options.scene = "perturbed-chain";
  options.iterations = 100;
  options.frames_are_sweeps = true;
  cl::add_common_options(app, options,
                         cl::kFlagScene | cl::kFlagIterations | cl::kFlagOut | cl::kFlagSummary | cl::kFlagFrames);
  app.get_option("--iterations").description("Gauss-Seidel sweeps over all springs (this lab has no time steps)");
  LabOptions lab;
  const std::vector<std::string> orders{"forward", "reverse", "random"};
  app.add_option("--order", lab.order, "spring order of every sweep (random: a new shuffle per sweep)")
      .one_of(orders)
      .capture_default_str();
  app.add_option("--seed", lab.seed, "seed of the random order").range(0, 2'000'000'000)
      .capture_default_str();
  app.add_option("--compare", lab.compare, "also run the same sweeps in this order and compare the final states")
      .one_of(orders);
  app.add_option("--tolerance", lab.tolerance, "max strain error that counts as converged")
      .positive()
      .capture_default_str();
  return cl::run_main(app, argc, argv, [&] { return run(options, lab); });
}
