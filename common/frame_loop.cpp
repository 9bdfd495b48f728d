#include "common/frame_loop.h"

#include <algorithm>
#include <memory>
#include <optional>
#include <stdexcept>

#include "common/health.h"
#include "common/obj.h"
#include "common/output.h"
#include "common/timer.h"
#include "common/trajectory.h"
#include "common/window_means.h"

namespace cl {

namespace {

// The CSV history, the OBJ frames and the trajectory of one run.
class FrameWriter {
 public:
  FrameWriter(const FrameOutput& output, const FramePlan& plan) : output_(output), last_frame_(plan.frames) {
    if (!output.csv_path.empty()) {
      std::vector<std::string> columns{output.index_column, "time"};
      columns.insert(columns.end(), output.columns.begin(), output.columns.end());
      columns.push_back("status");
      table_.emplace(columns);
    }
    if (output.trajectory_every > 0) {
      if (output.scene == nullptr) throw std::invalid_argument("run_frame_loop: a trajectory needs FrameOutput::scene");
      TrajectoryIdentity identity{output.lab, output.method, plan.energy_name, "s"};
      trajectory_.emplace(output.trajectory_dir, output.trajectory_every, *output.scene, identity);
      trajectory_->reserve(trajectory_frames_kept(plan.frames, output.trajectory_every) + 1);
    }
  }

  // One judged frame: its CSV row with `status`, its OBJ when it is healthy
  // and due, its trajectory frame when due (or last, or stopping).
  void add(const FrameEvent& event, const FrameMeasure& measure, const std::string& status) {
    if (table_) {
      std::vector<CsvCell> cells{static_cast<long long>(event.frame), event.time};
      cells.insert(cells.end(), measure.row.begin(), measure.row.end());
      cells.emplace_back(status);
      table_->add_row(cells);
    }
    const bool last = event.frame == last_frame_;
    const bool due = output_.obj_every > 0 && (event.frame % output_.obj_every == 0 || last);
    if (due && event.problem.empty() && output_.scene != nullptr) {
      write_frame_obj(output_.obj_dir, output_.lab, *output_.scene, event.state.x, event.frame, event.time);
      ++obj_frames_;
    }
    if (trajectory_ && (trajectory_->due(event.frame) || last || !event.problem.empty())) {
      trajectory_->add(event.frame, event.time, event.state.x, measure.energy, status);
    }
  }

  // Writes the history and the trajectory (when asked for).
  void finish(FrameLoopResult& result) const {
    if (table_) table_->write(output_.csv_path);
    if (trajectory_) {
      trajectory_->finish();
      result.trajectory_frames = trajectory_->frames_kept();
    }
    result.obj_frames = obj_frames_;
  }

 private:
  const FrameOutput& output_;
  int last_frame_;
  std::optional<CsvTable> table_;
  std::optional<TrajectoryWriter> trajectory_;
  int obj_frames_ = 0;
};

}  // namespace

FramePlan frame_plan(int frames, double dt, double energy_scale) {
  FramePlan plan;
  plan.frames = frames;
  plan.dt = dt;
  plan.energy_scale = energy_scale;
  return plan;
}

namespace {
// A function's own argument check that fires inside a step (a student
// function's std::invalid_argument) is that step's failure, reported with the
// step and its likely cause like any other problem, not a bare "invalid
// argument" after the run's files were started (docs/DESIGN.md §3).
StepVerdict guarded_step(const StepFunction& step, int frame) {
  try {
    return step(frame);
  } catch (const std::invalid_argument& refusal) {
    StepVerdict verdict;
    verdict.taken = false;
    verdict.problem = "step " + std::to_string(frame) + " could not be taken: a function refused its input (" +
                      refusal.what() + "); the run's state left that function's range, or an earlier result was wrong";
    return verdict;
  }
}
}  // namespace

FrameLoopResult run_frame_loop(Particles& state, const StepFunction& step, const MeasureFunction& measure,
                               const FramePlan& plan, const FrameOutput& output, const FrameHook& on_frame) {
  stop_if_checking();  // --check: a run that got here without start_run stops before its first step
  if (plan.frames < 0 || plan.window_frames < 0 || !(plan.settle_tolerance >= 0.0)) {
    throw std::invalid_argument("run_frame_loop: needs frames >= 0, window_frames >= 0, settle_tolerance >= 0");
  }
  FrameLoopResult result;
  FrameWriter writer(output, plan);
  // Judges one frame: the hook, then the output; true when the run goes on.
  auto judge = [&](int frame, const FrameMeasure& measured, const std::string& problem, const std::string& status) {
    const FrameEvent event{frame, frame * plan.dt, state, problem};
    if (on_frame) on_frame(event);
    writer.add(event, measured, status);
    if (problem.empty()) return true;
    result.problem = problem;
    result.problem_frame = frame;
    result.status = status;
    return false;
  };
  auto status_of = [&](const std::string& problem) { return problem.empty() ? std::string("ok") : output.problem_prefix + problem; };
  const bool check_energy = plan.energy_scale > 0.0 && plan.energy_verdict != EnergyVerdict::kOff;

  FrameMeasure measured = measure(0, 0.0);
  result.energy_start = result.energy_end = measured.energy;
  std::string problem = health_problem(state, measured.strain);
  if (problem.empty()) problem = measured.problem;
  result.status = "ok";
  if (!judge(0, measured, problem, status_of(problem))) {
    writer.finish(result);
    return result;
  }

  std::vector<WindowMeans> windows;
  for (int f = 1; f <= plan.frames; ++f) {
    const Timer timer;
    const StepVerdict verdict = guarded_step(step, f);
    const double seconds = verdict.seconds >= 0.0 ? verdict.seconds : timer.seconds();
    result.seconds += seconds;
    measured = measure(f, seconds);
    if (!verdict.taken) {
      result.step_failed = true;
      judge(f, measured, verdict.problem, verdict.problem);
      break;
    }
    result.frames_done = f;
    result.energy_end = measured.energy;
    const double rise = result.energy_end - result.energy_start;
    result.max_energy_rise = std::max(result.max_energy_rise, rise);
    problem = verdict.problem;
    if (problem.empty()) problem = health_problem(state, measured.strain);
    if (problem.empty()) problem = measured.problem;
    if (problem.empty() && check_energy) {
      const std::string rose = energy_rise_problem(rise, plan.energy_scale, plan.energy_name);
      if (plan.energy_verdict == EnergyVerdict::kStop) {
        problem = rose;
      } else if (!rose.empty() && result.energy_exceeded_frame < 0) {
        result.energy_exceeded_frame = f;
        result.energy_exceeded = rose;
      }
    }
    if (!judge(f, measured, problem, status_of(problem))) break;
    if (plan.window_frames == 0 || measured.windowed.empty()) continue;

    if (windows.empty()) windows.assign(measured.windowed.size(), WindowMeans(plan.window_frames));
    bool complete = false;
    for (std::size_t w = windows.size(); w-- > 0;) complete = windows[w].add(measured.windowed[w]);
    if (!complete) continue;
    if (result.windows_done > 0) result.previous_window_means = result.window_means;
    result.window_means.clear();
    for (const WindowMeans& window : windows) result.window_means.push_back(window.last());
    result.windows_done = windows[0].windows_done();
    result.window_spread = windows[0].relative_spread();
    if (windows[0].settled(plan.settle_tolerance) && f >= plan.settle_not_before) {
      result.settled = true;
      break;
    }
  }
  writer.finish(result);
  return result;
}

}  // namespace cl
