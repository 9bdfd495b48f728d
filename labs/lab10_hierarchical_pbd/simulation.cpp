// Lab 10 — given code: the step, the frame loop and the convergence measurement.
#include "simulation.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "common/timer.h"
#include "gauss_seidel.h"

namespace cl::lab10 {

long long projections_per_pass(const ClothHierarchy& hierarchy, const std::vector<int>& iterations) {
  long long total = 0;
  const std::size_t levels = std::min(iterations.size(), hierarchy.levels.size());
  for (std::size_t l = 0; l < levels; ++l) {
    total += static_cast<long long>(iterations[l]) * static_cast<long long>(hierarchy.levels[l].springs.size());
  }
  return total;
}

namespace {

void require_dt(double dt, const char* who) {
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    throw std::invalid_argument(std::string(who) + ": dt must be finite and > 0 (got " + std::to_string(dt) + ")");
  }
}

// p = x + Δt (v + Δt g) for movable particles, p = x for pinned ones.
Eigen::Matrix3Xd predict(const Particles& particles, double dt, const Eigen::Vector3d& gravity) {
  Eigen::Matrix3Xd predicted = particles.x;
  for (Eigen::Index p = 0; p < particles.size(); ++p) {
    if (particles.inv_mass[p] > 0.0) {
      const Eigen::Vector3d velocity = particles.v.col(p) + dt * gravity;
      predicted.col(p) += dt * velocity;
    }
  }
  return predicted;
}


}  // namespace

void hpbd_step(Particles& particles, const ClothHierarchy& hierarchy, const HpbdSettings& settings) {
  require_dt(settings.dt, "hpbd_step");
  if (particles.v.cols() != particles.size() || particles.inv_mass.size() != particles.size()) {
    throw std::invalid_argument("hpbd_step: x, v and inv_mass disagree in size");
  }
  Eigen::Matrix3Xd predicted = predict(particles, settings.dt, settings.gravity);
  solve_hierarchy(predicted, hierarchy, settings.iterations);
  particles.v = (predicted - particles.x) / settings.dt;
  particles.x = predicted;
}

RunResult run_frames(Particles& particles, const ClothHierarchy& hierarchy, const HpbdSettings& settings,
                     int frames, const FrameCallback& on_frame, const FrameOutput& output) {
  if (frames < 0) throw std::invalid_argument("run_frames: frames must be >= 0 (got " + std::to_string(frames) + ")");
  if (hierarchy.levels.empty()) throw std::invalid_argument("run_frames: the hierarchy has no levels");
  RunResult result;
  const FramePlan loop = frame_plan(frames, settings.dt, energy_scale(particles, settings.gravity, settings.dt));

  const long long per_step = projections_per_pass(hierarchy, settings.iterations);
  FrameRecord record;
  auto step = [&](int) {
    hpbd_step(particles, hierarchy, settings);
    result.projections += per_step;
    return StepVerdict{};
  };
  auto measure = [&](int f, double seconds) {
    record = FrameRecord{};
    record.frame = f;
    record.time = f * settings.dt;
    record.strain = strain_stats(particles.x, hierarchy.levels.front().springs);
    record.kinetic = kinetic_energy(particles);
    record.potential = potential_energy(particles, settings.gravity);
    record.seconds = seconds;
    const double total = record.kinetic + record.potential;
    return FrameMeasure{record.strain,
                        total,
                        {},
                        {record.strain.max, record.strain.rms, record.kinetic, record.potential, total, seconds},
                        {}};
  };
  const FrameLoopResult run = run_frame_loop(particles, step, measure, loop, output, record_hook(record, on_frame));
  copy_outcome(run, result, result.frames_done, result.problem_frame);
  result.energy_start = run.energy_start;
  result.energy_end = run.energy_end;
  result.obj_frames = run.obj_frames;
  return result;
}

std::vector<std::string> frame_columns() {
  return {"max_strain", "rms_strain", "kinetic", "potential", "total_energy", "seconds"};
}

ConvergenceResult converge_one_step(const Particles& particles, const ClothHierarchy& hierarchy, double dt,
                                    const Eigen::Vector3d& gravity, const std::vector<int>& iterations,
                                    const std::vector<double>& targets, int max_sweeps) {
  require_dt(dt, "converge_one_step");
  if (hierarchy.levels.empty() || iterations.size() != hierarchy.levels.size()) {
    throw std::invalid_argument("converge_one_step: needs one iteration count per level (" +
                                std::to_string(hierarchy.levels.size()) + "), got " +
                                std::to_string(iterations.size()));
  }
  if (iterations.front() < 1 || max_sweeps < 0 ||
      std::any_of(iterations.begin(), iterations.end(), [](int k) { return k < 0; })) {
    throw std::invalid_argument("converge_one_step: needs iterations >= 0, at least 1 on the cloth, max_sweeps >= 0");
  }
  if (particles.v.cols() != particles.size() || particles.inv_mass.size() != particles.size()) {
    throw std::invalid_argument("converge_one_step: x, v and inv_mass disagree in size");
  }
  const HierarchyLevel& cloth = hierarchy.levels.front();
  ConvergenceResult result;
  for (const double target : targets) result.targets.push_back(TargetReached{target, false, {}});

  std::vector<int> coarse_pass = iterations;
  coarse_pass.front() = 0;
  const long long coarse_projections = projections_per_pass(hierarchy, coarse_pass);
  const bool has_coarse = coarse_projections > 0;
  std::vector<int> order(cloth.springs.size());
  std::iota(order.begin(), order.end(), 0);
  const long long per_sweep = static_cast<long long>(cloth.springs.size());

  Eigen::Matrix3Xd x = predict(particles, dt, gravity);
  ConvergenceSample sample;
  for (;;) {
    sample.strain = strain_stats(x, cloth.springs);
    result.samples.push_back(sample);
    bool all_reached = true;
    for (TargetReached& target : result.targets) {
      if (!target.reached && sample.strain.max <= target.target) {
        target.reached = true;
        target.at = sample;
      }
      all_reached = all_reached && target.reached;
    }
    if (all_reached || sample.sweeps >= max_sweeps || !std::isfinite(sample.strain.max)) break;
    const Timer timer;
    if (sample.sweeps % iterations.front() == 0) {  // a new pass: the coarse levels first
      if (has_coarse) solve_hierarchy(x, hierarchy, coarse_pass);
      sample.passes += 1;
      sample.projections += coarse_projections;
    }
    lab02::gauss_seidel_sweep(x, cloth.inv_mass, cloth.springs, order);
    sample.seconds += timer.seconds();
    sample.sweeps += 1;
    sample.projections += per_sweep;
  }
  return result;
}

}  // namespace cl::lab10
