#pragma once
// The one frame loop of every time-stepping lab (04–13): it steps a state
// frame by frame, measures it after every frame, and owns what every lab
// decides alike — the health verdict (common/health.h), the energy verdict,
// the settle windows (common/window_means.h), the per-frame CSV history, the
// OBJ frames — and stops at the first problem. A lab gives only its step and
// what one of its frames measures.
//
// Frame 0 is the state before any step; frame f the state after the f-th step.
#include <functional>
#include <string>
#include <vector>

#include "common/csv.h"
#include "common/metrics.h"
#include "common/particles.h"
#include "common/scene.h"

namespace cl {

// What a step says about itself; the default is a step that went fine.
struct StepVerdict {
  // Not empty: the step reports a problem. With taken = true the state is the
  // step's result and the problem is the frame's verdict (before health is
  // looked at; lab 06's solver); the CSV status is "<problem_prefix><problem>".
  // With taken = false the step could not be done (lab 07's singular system):
  // the frame is not counted in frames_done, and the status is `problem` as it is.
  std::string problem;
  bool taken = true;
  // >= 0: the step's own measure of its wall time, s (lab 06's solver); < 0:
  // the loop's clock around the step function.
  double seconds = -1.0;
};

// What a lab measures after one frame (the loop calls it for frame 0, for every
// step taken, and for a step that could not be taken).
struct FrameMeasure {
  StrainStats strain;            // over the scene's springs: health_problem's input
  double energy = 0.0;           // J, the energy whose rise the verdict checks (FramePlan::energy_name)
  std::vector<double> windowed;  // values averaged over the settle windows; [0] decides settling
  std::vector<CsvCell> row;      // the lab's CSV cells of this frame (FrameOutput::columns)
  std::string problem;           // the lab's own verdict, looked at after health and before energy
};

using StepFunction = std::function<StepVerdict(int frame)>;
// frame, and the wall time of its step (s; 0 for frame 0).
using MeasureFunction = std::function<FrameMeasure(int frame, double seconds)>;

// What the energy verdict does with a rise above the scene's scale.
enum class EnergyVerdict {
  kStop,    // the frame's problem: the run stops there (reported as diverged)
  kReport,  // noted once (FrameLoopResult::energy_exceeded_*), the run goes on
            // (lab 05: a limiter that keeps the band while the step blows up)
  kOff,     // not looked at
};

struct FramePlan {
  int frames = 0;                       // frames to run (the most, when settling)
  double dt = 0.0;                      // s per frame: frame f is at time f · dt
  double energy_scale = 0.0;            // J, the most the scene may gain (<= 0: no energy verdict)
  EnergyVerdict energy_verdict = EnergyVerdict::kStop;
  std::string energy_name = "total energy";  // what FrameMeasure::energy sums, for the message
  int window_frames = 0;                // frames per settle window (0: no windows)
  // > 0: stop after the first window at which the means of windowed[0] over
  // the last three windows agree to this relative spread (WindowMeans::settled),
  // once frame settle_not_before has been passed.
  double settle_tolerance = 0.0;
  int settle_not_before = -1;
};

// A frame as the loop has judged it: what the lab's hook sees (problem empty
// when the frame is healthy).
struct FrameEvent {
  int frame = 0;
  double time = 0.0;  // s
  const Particles& state;
  const std::string& problem;
};
using FrameHook = std::function<void(const FrameEvent&)>;

// What the loop writes. Everything empty: nothing.
struct FrameOutput {
  // Per-frame history: one row per frame (frame 0 and the frame that stopped
  // the run included), columns `index_column`, "time", `columns`, "status"
  // ("ok", "<problem_prefix><problem>", or a failed step's own problem).
  // Written to csv_path when the loop ends, also for a run that stopped.
  std::string csv_path;
  std::vector<std::string> columns;
  std::string index_column = "frame";
  std::string problem_prefix = "diverged: ";
  // OBJ meshes (common/obj.h) of healthy frames: every obj_every-th frame and
  // the last planned one (FramePlan::frames), into obj_dir.
  int obj_every = 0;                    // 0: none
  std::string obj_dir;
  std::string lab;
  const Scene* scene = nullptr;         // its triangles or springs make the mesh
  // The trajectory (common/trajectory.h, for ./course view): every
  // trajectory_every-th judged frame, the last planned one and the frame that
  // stopped the run, with its positions, strains, time, FrameMeasure::energy
  // and status, into trajectory_dir/trajectory.{json,bin} when the loop ends
  // (also for a run that stopped). `lab`, `scene` (needed) and `method` name
  // the run. 0: none.
  int trajectory_every = 0;
  std::string trajectory_dir;
  std::string method;
};

struct FrameLoopResult {
  int frames_done = 0;               // steps taken (a step that could not be taken is not counted)
  double seconds = 0.0;              // wall time of all steps, s
  double energy_start = 0.0;         // FrameMeasure::energy at frame 0, J
  double energy_end = 0.0;           // at the last frame counted
  double max_energy_rise = 0.0;      // max over frames counted of energy − energy_start, J (>= 0)
  std::string problem;               // empty unless the run stopped at a problem
  int problem_frame = -1;
  bool step_failed = false;          // the problem is a step that could not be taken
  std::string status;                // "ok", or the stopping frame's CSV status
  // kReport: the first frame whose energy rose above the scale, and the verdict text.
  int energy_exceeded_frame = -1;
  std::string energy_exceeded;
  // Settle windows (FramePlan::window_frames > 0), of the healthy frames 1, 2, …
  int windows_done = 0;
  std::vector<double> window_means;           // the newest complete window's, one per windowed value
  std::vector<double> previous_window_means;  // the window before it (empty: none)
  double window_spread = -1.0;                // WindowMeans::relative_spread of windowed[0]
  bool settled = false;
  int obj_frames = 0;                // OBJ files written
  int trajectory_frames = 0;         // frames kept in the trajectory
};

// The plan most labs start from: `frames` frames of `dt` s, the energy verdict
// stopping a rise above `energy_scale` J, no windows.
FramePlan frame_plan(int frames, double dt, double energy_scale);

// Runs the loop on `state` (which the step function changes). `on_frame`, if
// set, is called for every judged frame before the output (the lab's own
// per-frame callback). Throws std::invalid_argument for frames < 0,
// window_frames < 0 or a settle tolerance that is not >= 0; whatever the step,
// the measure or the output throw passes through.
FrameLoopResult run_frame_loop(Particles& state, const StepFunction& step, const MeasureFunction& measure,
                               const FramePlan& plan, const FrameOutput& output = {},
                               const FrameHook& on_frame = nullptr);

// For a lab whose own per-frame callback takes its record and the state: the
// hook that writes the frame's verdict into record.problem and then calls
// `callback` (when set). `record` and `callback` must outlive the loop.
template <class Record, class Callback>
FrameHook record_hook(Record& record, const Callback& callback) {
  return [&record, &callback](const FrameEvent& event) {
    record.problem = event.problem;
    if (callback) callback(record, event.state);
  };
}

// Copies the outcome every lab's result reports alike: the frames (or steps)
// done into `done`, the wall time into result.seconds, the problem into
// result.problem and its frame into `at`.
template <class Result>
void copy_outcome(const FrameLoopResult& run, Result& result, int& done, int& at) {
  done = run.frames_done;
  result.seconds = run.seconds;
  result.problem = run.problem;
  at = run.problem_frame;
}

}  // namespace cl
