#pragma once
// Lab 04 — given code: the frame loop around pbd_step, shared by the driver and
// the graded tests. It owns the state; pbd_step stays stateless.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/frame_loop.h"
#include "common/health.h"
#include "common/metrics.h"
#include "pbd.h"

namespace cl::lab04 {

// One frame of length frame.dt, done as `substeps` PBD steps of frame.dt / substeps
// (each with frame.iterations sweeps). Throws std::invalid_argument for substeps < 1.
void advance_frame(Particles& particles, const ConstraintSet& constraints, const PbdSettings& frame,
                   int substeps);

// health_problem, energy_scale, energy_rise_problem and kUnstableStrain live in
// common/health.h; the averaging windows and the settle test in common/window_means.h.

// What one frame looked like after it was computed (frame 0: the initial state).
struct FrameRecord {
  int frame = 0;
  double time = 0.0;        // s
  StrainStats strain;       // over the scene's springs
  double kinetic = 0.0;     // J
  double potential = 0.0;   // J, zero at the origin
  double seconds = 0.0;     // wall time of this frame's steps
  std::string problem;      // empty when healthy (see run_frames)
};

struct RunPlan {
  int frames = 0;                  // frames to run; the most, when settling
  int window_frames = 60;          // frames per averaging window (windows are frames 1…W, W+1…2W, …)
  // > 0: stop after the first window at which the mean max strain of the last
  // three windows agree to this relative spread, (max − min) <= tol · last, and
  // energy_frame has been passed (common/window_means.h).
  double settle_tolerance = 0.0;
  int energy_frame = -1;           // record the total energy after this frame (−1: none)
};

struct RunResult {
  int frames_done = 0;
  int windows_done = 0;                  // complete windows
  double window_max_strain = 0.0;        // last complete window: mean of the per-frame max strain
  double window_rms_strain = 0.0;        // last complete window: mean of the per-frame RMS strain
  double previous_window_max_strain = -1.0;  // the window before it (-1: none)
  double window_spread = -1.0;           // (max − min) / last over the last three windows' means (-1: < 3)
  bool settled = false;                  // stopped by settle_tolerance
  double energy_start = 0.0;             // kinetic + potential, J
  double energy_end = 0.0;
  double energy_at_mark = 0.0;           // after plan.energy_frame, if it was reached
  double max_energy_rise = 0.0;          // max over frames of E(t) − E(0), J (>= 0)
  double energy_scale = 0.0;             // see energy_scale(), J
  double seconds = 0.0;                  // wall time of all steps
  std::string problem;                   // empty unless the run diverged (it stops there)
  int problem_frame = -1;
  int obj_frames = 0;                    // OBJ files written (FrameOutput)
};

using FrameCallback = std::function<void(const FrameRecord&, const Particles&)>;

// Runs `particles` forward frame by frame (advance_frame) in common/frame_loop.h's
// loop, measuring after every frame and calling `on_frame` (if set) for frame 0
// and each frame after it. Stops at the first unhealthy frame (health_problem,
// or a total energy more than energy_scale above its start) and says why in
// RunResult::problem. Potential energy is measured in frame.gravity. `output`
// asks the loop for the per-frame CSV (frame_columns()) and OBJ frames.
RunResult run_frames(Particles& particles, const ConstraintSet& constraints, const PbdSettings& frame,
                     int substeps, const RunPlan& plan, const FrameCallback& on_frame = nullptr,
                     const FrameOutput& output = {});

// The lab's columns of the per-frame CSV: max_strain, rms_strain, kinetic,
// potential, total_energy (J), seconds (wall time of the frame's steps).
std::vector<std::string> frame_columns();

}  // namespace cl::lab04
