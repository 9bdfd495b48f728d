// Lab 04 — given code: the frame loop around pbd_step.
#include "simulation.h"

#include <algorithm>
#include <stdexcept>
#include <string>


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

RunResult run_frames(Particles& particles, const ConstraintSet& constraints, const PbdSettings& frame, int substeps,
                     const RunPlan& plan, const FrameCallback& on_frame, const FrameOutput& output) {
  if (plan.frames < 0 || plan.window_frames < 1 || !(plan.settle_tolerance >= 0.0)) {
    throw std::invalid_argument("run_frames: needs frames >= 0, window_frames >= 1, settle_tolerance >= 0");
  }
  RunResult result;
  result.energy_scale = energy_scale(particles, frame.gravity, frame.dt);
  FramePlan loop = frame_plan(plan.frames, frame.dt, result.energy_scale);
  loop.window_frames = plan.window_frames;
  loop.settle_tolerance = plan.settle_tolerance;
  loop.settle_not_before = plan.energy_frame;

  FrameRecord record;
  auto step = [&](int) {
    advance_frame(particles, constraints, frame, substeps);
    return StepVerdict{};
  };
  auto measure = [&](int f, double seconds) {
    record = FrameRecord{};
    record.frame = f;
    record.time = f * frame.dt;
    record.strain = strain_stats(particles.x, constraints.springs);
    record.kinetic = kinetic_energy(particles);
    record.potential = potential_energy(particles, frame.gravity);
    record.seconds = seconds;
    const double total = record.kinetic + record.potential;
    if (f == plan.energy_frame) result.energy_at_mark = total;
    return FrameMeasure{record.strain,
                        total,
                        {record.strain.max, record.strain.rms},
                        {record.strain.max, record.strain.rms, record.kinetic, record.potential, total, seconds},
                        {}};
  };
  const FrameLoopResult run = run_frame_loop(particles, step, measure, loop, output, record_hook(record, on_frame));

  copy_outcome(run, result, result.frames_done, result.problem_frame);
  result.windows_done = run.windows_done;
  if (run.windows_done > 0) {
    result.window_max_strain = run.window_means[0];
    result.window_rms_strain = run.window_means[1];
  }
  if (!run.previous_window_means.empty()) result.previous_window_max_strain = run.previous_window_means[0];
  result.window_spread = run.window_spread;
  result.settled = run.settled;
  result.energy_start = run.energy_start;
  result.energy_end = run.energy_end;
  result.max_energy_rise = run.max_energy_rise;
  result.obj_frames = run.obj_frames;
  return result;
}

// The columns of the per-frame history that run_frames writes (FrameOutput::columns).
std::vector<std::string> frame_columns() {
  return {"max_strain", "rms_strain", "kinetic", "potential", "total_energy", "seconds"};
}

}  // namespace cl::lab04
