// lab01_single_spring: project every spring of a scene once, in file order,
// and report the strain before and after. With --sweep-mass-ratio: the share
// of the correction each end takes as m_i/m_j runs from 1e-6 to 1e6.
#include <cmath>
#include <cstdio>
#include <iostream>

#include "common/cli.h"
#include "common/csv.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/summary.h"
#include "common/timer.h"
#include "single_spring.h"

namespace {

constexpr const char* kLab = CL_LAB_NAME;

void write_pass_csv(const std::string& out, const cl::Scene& scene, const Eigen::Matrix3Xd& before,
                    const Eigen::Matrix3Xd& after) {
  cl::CsvTable springs({"spring", "i", "j", "rest", "length_before", "length_after", "strain_before",
                        "strain_after"});
  for (std::size_t s = 0; s < scene.springs.size(); ++s) {
    const cl::Spring& spring = scene.springs[s];
    springs.add_row({static_cast<long long>(s), static_cast<long long>(spring.i), static_cast<long long>(spring.j),
                     spring.rest_length, (before.col(spring.i) - before.col(spring.j)).norm(),
                     (after.col(spring.i) - after.col(spring.j)).norm(), cl::strain_error(before, spring),
                     cl::strain_error(after, spring)});
  }
  cl::CsvTable positions({"particle", "inv_mass", "x_before", "y_before", "z_before", "x_after", "y_after",
                          "z_after"});
  for (Eigen::Index p = 0; p < before.cols(); ++p) {
    positions.add_row({static_cast<long long>(p), scene.particles.inv_mass[p], before(0, p), before(1, p),
                       before(2, p), after(0, p), after(1, p), after(2, p)});
  }
  springs.write(cl::join_path(out, "springs.csv"));
  positions.write(cl::join_path(out, "positions.csv"));
}

// Share of the correction taken by end i: ‖Δx_i‖ / (‖Δx_i‖ + ‖Δx_j‖); the
// analytic value is w_i / (w_i + w_j) = m_j / (m_i + m_j).
int sweep_mass_ratio(const cl::Scene& scene, const std::string& out) {
  if (scene.springs.empty()) throw cl::InputError(scene.source + ": springs: --sweep-mass-ratio needs a spring");
  const cl::Spring& spring = scene.springs.front();
  const Eigen::Vector3d x_i = scene.particles.x.col(spring.i);
  const Eigen::Vector3d x_j = scene.particles.x.col(spring.j);
  if ((x_i - x_j).norm() == spring.rest_length) {
    throw cl::InputError(scene.source + ": springs[0]: --sweep-mass-ratio needs a spring away from its rest length");
  }
  cl::start_run(out);  // only once the input is known good
  cl::CsvTable table({"mass_ratio", "share_i", "share_j", "expected_share_i"});
  std::printf("%12s %14s %14s %14s\n", "m_i/m_j", "share_i", "share_j", "expected_i");
  constexpr int kPerDecade = 4;
  for (int step = -6 * kPerDecade; step <= 6 * kPerDecade; ++step) {
    const double ratio = std::pow(10.0, static_cast<double>(step) / kPerDecade);
    const double inv_mass_i = 1.0 / ratio;  // m_j = 1 kg
    const double inv_mass_j = 1.0;
    const cl::lab01::DistanceCorrection correction =
        cl::lab01::project_distance(x_i, x_j, inv_mass_i, inv_mass_j, spring.rest_length);
    const double moved_i = correction.dx_i.norm();
    const double moved_j = correction.dx_j.norm();
    const double share_i = moved_i / (moved_i + moved_j);
    const double expected = inv_mass_i / (inv_mass_i + inv_mass_j);
    table.add_row({ratio, share_i, moved_j / (moved_i + moved_j), expected});
    if (step % kPerDecade == 0) std::printf("%12.0e %14.6e %14.6e %14.6e\n", ratio, share_i, 1.0 - share_i, expected);
  }
  if (!out.empty()) table.write(cl::join_path(out, "mass_ratio_sweep.csv"));
  return 0;
}

int run(const cl::CommonOptions& options, bool sweep) {
  const cl::Scene scene = cl::load_scene_for(options, CL_LAB_SCENE_DIR);
  if (sweep) return sweep_mass_ratio(scene, options.out);
  cl::start_run(options);

  const Eigen::Matrix3Xd before = scene.particles.x;
  Eigen::Matrix3Xd x = before;
  const cl::Timer timer;
  for (const cl::Spring& spring : scene.springs) {
    const cl::lab01::DistanceCorrection correction = cl::lab01::project_distance(
        x.col(spring.i), x.col(spring.j), scene.particles.inv_mass[spring.i], scene.particles.inv_mass[spring.j],
        spring.rest_length);
    x.col(spring.i) += correction.dx_i;
    x.col(spring.j) += correction.dx_j;
  }
  const double seconds = timer.seconds();
  if (!cl::all_finite(x)) throw std::runtime_error("a projection produced a non-finite position");

  const cl::StrainStats strain_before = cl::strain_stats(before, scene.springs);
  const cl::StrainStats strain_after = cl::strain_stats(x, scene.springs);
  std::printf("%s: scene %s, %zu springs, %ld particles, one projection each in file order\n", kLab,
              scene.name.c_str(), scene.springs.size(), static_cast<long>(x.cols()));
  std::printf("  strain error  before: max %.3e  rms %.3e\n", strain_before.max, strain_before.rms);
  std::printf("                after:  max %.3e  rms %.3e\n", strain_after.max, strain_after.rms);
  std::printf("  time %.3e s (%.3e s per projection)\n", seconds,
              scene.springs.empty() ? 0.0 : seconds / static_cast<double>(scene.springs.size()));

  if (!options.out.empty()) write_pass_csv(options.out, scene, before, x);
  if (!options.summary.empty()) {
    cl::RunSummary summary;
    summary.lab = kLab;
    summary.method = "single-pass";
    summary.scene = scene.name;
    summary.positions = x;
    summary.max_strain_error = strain_after.max;
    summary.seconds = seconds;
    summary.extra["max_strain_error_before"] = strain_before.max;
    summary.extra["rms_strain_error"] = strain_after.rms;
    cl::write_summary(options.summary, summary);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{
      "Lab 01: project every spring of a scene once and measure the strain before and after.",
      CL_PROGRAM_NAME};
  cl::CommonOptions options;
  options.scene = "two-particles";
  cl::add_common_options(app, options, cl::kFlagScene | cl::kFlagOut | cl::kFlagSummary);
  bool sweep = false;
  app.add_flag("--sweep-mass-ratio", sweep,
               "project the scene's first spring for m_i/m_j from 1e-6 to 1e6 and write mass_ratio_sweep.csv");
  return cl::run_main(app, argc, argv, [&] { return run(options, sweep); });
}
