// Lab 04 — given code: the frame loop around pbd_step.
#include "simulation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <stdexcept>
#include <string>

#include "common/timer.h"

namespace cl::lab04 {

void advance_frame(Particles& particles, const ConstraintSet& constraints, const PbdSettings& frame,
                   int substeps) {
  if (substeps < 1) {
    throw std::invalid_argument("advance_frame: substeps must be >= 1 (got " + std::to_string(substeps) + ")");
  }
  PbdSettings step = frame;
  step.dt = frame.dt / substeps;
  for (int s = 0; s < substeps; ++s) pbd_step(particles, constraints, step);
}

namespace {
FrameRecord measure(int frame, double time, const Particles& particles, const ConstraintSet& constraints,
                    const Eigen::Vector3d& gravity, double seconds) {
  FrameRecord record;
  record.frame = frame;
  record.time = time;
  record.strain = strain_stats(particles.x, constraints.springs);
  record.kinetic = kinetic_energy(particles);
  record.potential = potential_energy(particles, gravity);
  record.seconds = seconds;
  return record;
}
}  // namespace

RunResult run_frames(Particles& particles, const ConstraintSet& constraints, const PbdSettings& frame, int substeps,
                     const RunPlan& plan, const FrameCallback& on_frame) {
  if (plan.frames < 0 || plan.window_frames < 1 || !(plan.settle_tolerance >= 0.0)) {
    throw std::invalid_argument("run_frames: needs frames >= 0, window_frames >= 1, settle_tolerance >= 0");
  }
  RunResult result;
  result.energy_scale = energy_scale(particles, frame.gravity, frame.dt);
  FrameRecord record = measure(0, 0.0, particles, constraints, frame.gravity, 0.0);
  result.energy_start = record.kinetic + record.potential;
  result.energy_end = result.energy_start;
  if (plan.energy_frame == 0) result.energy_at_mark = result.energy_start;
  record.problem = health_problem(particles, record.strain);
  if (on_frame) on_frame(record, particles);
  result.problem = record.problem;
  if (!result.problem.empty()) {
    result.problem_frame = 0;
    return result;
  }

  std::deque<double> window_means;  // the last three windows' mean max strain
  double sum_max = 0.0, sum_rms = 0.0;
  for (int f = 1; f <= plan.frames; ++f) {
    const Timer timer;
    advance_frame(particles, constraints, frame, substeps);
    const double seconds = timer.seconds();
    result.seconds += seconds;
    record = measure(f, f * frame.dt, particles, constraints, frame.gravity, seconds);
    result.frames_done = f;
    result.energy_end = record.kinetic + record.potential;
    if (f == plan.energy_frame) result.energy_at_mark = result.energy_end;
    const double rise = result.energy_end - result.energy_start;
    result.max_energy_rise = std::max(result.max_energy_rise, rise);
    record.problem = health_problem(particles, record.strain);
    if (record.problem.empty() && result.energy_scale > 0.0 && rise > result.energy_scale) {
      char text[160];
      std::snprintf(text, sizeof text, "total energy rose %.3g J above its start (more than the scene's %.3g J): unstable",
                    rise, result.energy_scale);
      record.problem = text;
    }
    if (on_frame) on_frame(record, particles);
    result.problem = record.problem;
    if (!result.problem.empty()) {
      result.problem_frame = f;
      return result;
    }
    sum_max += record.strain.max;
    sum_rms += record.strain.rms;
    if (f % plan.window_frames != 0) continue;

    // A window is complete.
    if (result.windows_done > 0) result.previous_window_max_strain = result.window_max_strain;
    result.window_max_strain = sum_max / plan.window_frames;
    result.window_rms_strain = sum_rms / plan.window_frames;
    ++result.windows_done;
    sum_max = sum_rms = 0.0;
    window_means.push_back(result.window_max_strain);
    if (window_means.size() > 3) window_means.pop_front();
    if (window_means.size() == 3) {
      const auto [low, high] = std::minmax_element(window_means.begin(), window_means.end());
      const double spread = *high - *low;
      const double last = window_means.back();
      result.window_spread = last > 0.0 ? spread / last : (spread > 0.0 ? 1.0 : 0.0);
      if (plan.settle_tolerance > 0.0 && spread <= plan.settle_tolerance * last && f >= plan.energy_frame) {
        result.settled = true;
        break;
      }
    }
  }
  return result;
}

}  // namespace cl::lab04
