// Lab 04 — given code: the frame loop around pbd_step.
#include "simulation.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "common/timer.h"
#include "common/window_means.h"

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

  WindowMeans max_strain(plan.window_frames), rms_strain(plan.window_frames);
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
    if (record.problem.empty()) record.problem = energy_rise_problem(rise, result.energy_scale);
    if (on_frame) on_frame(record, particles);
    result.problem = record.problem;
    if (!result.problem.empty()) {
      result.problem_frame = f;
      return result;
    }
    rms_strain.add(record.strain.rms);
    if (!max_strain.add(record.strain.max)) continue;

    // A window is complete.
    if (result.windows_done > 0) result.previous_window_max_strain = result.window_max_strain;
    result.window_max_strain = max_strain.last();
    result.window_rms_strain = rms_strain.last();
    result.windows_done = max_strain.windows_done();
    result.window_spread = max_strain.relative_spread();
    if (max_strain.settled(plan.settle_tolerance) && f >= plan.energy_frame) {
      result.settled = true;
      break;
    }
  }
  return result;
}

}  // namespace cl::lab04
