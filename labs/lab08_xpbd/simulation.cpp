// Lab 08 — given code: the frame loop around xpbd_step and lab 04's pbd_step.
#include "simulation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>


namespace cl::lab08 {

void advance_frame(Particles& particles, const lab04::ConstraintSet& constraints, const FrameSettings& frame,
                   Eigen::VectorXd& lambda) {
  if (frame.substeps < 1) {
    throw std::invalid_argument("advance_frame: substeps must be >= 1 (got " + std::to_string(frame.substeps) +
                                ")");
  }
  const double dt = frame.dt / frame.substeps;
  if (frame.method == Method::kPbd) {
    lab04::PbdSettings step;
    step.dt = dt;
    step.gravity = frame.gravity;
    step.iterations = frame.iterations;
    step.projection = lab04::Projection::kGaussSeidel;
    for (int s = 0; s < frame.substeps; ++s) lab04::pbd_step(particles, constraints, step);
    lambda.resize(0);
    return;
  }
  XpbdSettings step;
  step.dt = dt;
  step.gravity = frame.gravity;
  step.iterations = frame.iterations;
  for (int s = 0; s < frame.substeps; ++s) xpbd_step(particles, constraints, step, lambda);
}

double elastic_energy(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  double energy = 0.0;
  for (const Spring& spring : springs) {
    if (std::isinf(spring.stiffness)) continue;
    const double extension = (x.col(spring.i) - x.col(spring.j)).norm() - spring.rest_length;
    energy += 0.5 * spring.stiffness * extension * extension;
  }
  return energy;
}

double total_stretch(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  double stretch = 0.0;
  for (const Spring& spring : springs) stretch += (x.col(spring.i) - x.col(spring.j)).norm() - spring.rest_length;
  return stretch;
}

std::optional<double> hanging_chain_stretch(const Particles& particles, const std::vector<Spring>& springs,
                                            const Eigen::Vector3d& gravity) {
  const Eigen::Index n = particles.size();
  if (springs.empty() || static_cast<Eigen::Index>(springs.size()) != n - 1) return std::nullopt;
  if (particles.inv_mass[0] != 0.0) return std::nullopt;
  for (Eigen::Index p = 1; p < n; ++p) {
    if (!(particles.inv_mass[p] > 0.0)) return std::nullopt;
  }
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const Spring& spring = springs[s];
    const bool in_order = (spring.i == static_cast<int>(s) && spring.j == static_cast<int>(s) + 1) ||
                          (spring.j == static_cast<int>(s) && spring.i == static_cast<int>(s) + 1);
    if (!in_order || std::isinf(spring.stiffness)) return std::nullopt;
  }
  // Walk up from the free end, adding each bead's weight to what hangs below.
  double weight_below = 0.0, stretch = 0.0;
  for (Eigen::Index s = n - 2; s >= 0; --s) {
    weight_below += gravity.norm() / particles.inv_mass[s + 1];
    stretch += weight_below / springs[static_cast<std::size_t>(s)].stiffness;
  }
  return stretch;
}

namespace {
// PBD treats every spring as a hard constraint, which stores no energy: the
// elastic term is XPBD's only.
FrameRecord measure(int frame, double time, const Particles& particles, const lab04::ConstraintSet& constraints,
                    const FrameSettings& settings, double seconds) {
  const Eigen::Vector3d& gravity = settings.gravity;
  FrameRecord record;
  record.frame = frame;
  record.time = time;
  record.strain = strain_stats(particles.x, constraints.springs);
  record.total_stretch = total_stretch(particles.x, constraints.springs);
  record.kinetic = kinetic_energy(particles);
  record.potential = potential_energy(particles, gravity);
  record.elastic = settings.method == Method::kXpbd ? elastic_energy(particles.x, constraints.springs) : 0.0;
  record.seconds = seconds;
  return record;
}

double total(const FrameRecord& record) { return record.kinetic + record.potential + record.elastic; }

// The stability check watches kinetic + gravitational energy, as lab 04's does.
// The elastic term is left out on purpose: with too few sweeps XPBD leaves the
// springs far longer than the material would, and ½k(ℓ − L)² of that stretch
// is the solver's error, not energy the run could give back.
double mechanical(const FrameRecord& record) { return record.kinetic + record.potential; }
}  // namespace

RunResult run_frames(Particles& particles, const lab04::ConstraintSet& constraints, const FrameSettings& frame,
                     const RunPlan& plan, const FrameCallback& on_frame, const FrameOutput& output) {
  if (plan.frames < 0 || plan.window_frames < 1 || !(plan.settle_tolerance >= 0.0)) {
    throw std::invalid_argument("run_frames: needs frames >= 0, window_frames >= 1, settle_tolerance >= 0");
  }
  RunResult result;
  result.energy_scale = energy_scale(particles, frame.gravity, frame.dt);
  FramePlan loop = frame_plan(plan.frames, frame.dt, result.energy_scale);
  loop.energy_name = "kinetic + potential energy";
  loop.window_frames = plan.window_frames;
  loop.settle_tolerance = plan.settle_tolerance;

  FrameRecord record;
  auto step = [&](int) {
    advance_frame(particles, constraints, frame, result.lambda);
    return StepVerdict{};
  };
  auto measured = [&](int f, double seconds) {
    record = measure(f, f * frame.dt, particles, constraints, frame, seconds);
    result.energy_end = total(record);
    if (f == 0) result.energy_start = result.energy_end;
    result.max_energy_rise = std::max(result.max_energy_rise, result.energy_end - result.energy_start);
    return FrameMeasure{record.strain,
                        mechanical(record),
                        {record.total_stretch, record.strain.max},
                        {record.strain.max, record.strain.rms, record.total_stretch, record.kinetic, record.potential,
                         record.elastic, total(record), seconds},
                        {}};
  };
  const FrameLoopResult run = run_frame_loop(particles, step, measured, loop, output, record_hook(record, on_frame));

  copy_outcome(run, result, result.frames_done, result.problem_frame);
  result.windows_done = run.windows_done;
  if (run.windows_done > 0) {
    result.window_total_stretch = run.window_means[0];
    result.window_max_strain = run.window_means[1];
  }
  result.window_spread = run.window_spread;
  result.settled = run.settled;
  return result;
}

std::vector<std::string> frame_columns() {
  return {"max_strain", "rms_strain", "total_stretch", "kinetic", "potential", "elastic", "total_energy", "seconds"};
}

}  // namespace cl::lab08
