// common/frame_loop.h: the one frame loop of labs 04–10, on one particle whose
// step is written by hand (it gains a known speed per step), so that the
// frames, verdicts, windows and CSV rows the loop produces are known exactly.
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/frame_loop.h"
#include "common/health.h"
#include "common/output.h"
#include "tests/support/scratch.h"

using cl::test::ContainsText;
using Catch::Matchers::StartsWith;

namespace {

cl::Particles one_particle() {
  cl::Particles particles;
  particles.x = Eigen::Matrix3Xd::Zero(3, 1);
  particles.v = Eigen::Matrix3Xd::Zero(3, 1);
  particles.inv_mass = Eigen::VectorXd::Ones(1);
  return particles;
}

// The particle's kinetic energy ½ v², v raised by `kick` m/s each step.
struct Kicked {
  cl::Particles state = one_particle();
  double kick = 1.0;
  cl::StepFunction step() {
    return [this](int) {
      state.v(0, 0) += kick;
      state.x(0, 0) += state.v(0, 0);
      return cl::StepVerdict{};
    };
  }
  cl::MeasureFunction measure() {
    return [this](int, double) {
      const double v = state.v(0, 0);
      return cl::FrameMeasure{{}, 0.5 * v * v, {1.0}, {v}, {}};
    };
  }
};

// Output asking for the history in `scratch`/FILE.
cl::FrameOutput history_in(const cl::test::ScratchDir& scratch, const std::string& file) {
  cl::FrameOutput output;
  output.csv_path = scratch.file(file);
  return output;
}

std::vector<std::string> lines_of(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

}  // namespace

TEST_CASE("the frame loop runs every frame of a healthy run and judges frame 0 too", "[common][frame_loop]") {
  Kicked run;
  run.kick = 0.0;
  cl::FramePlan plan;
  plan.frames = 7;
  plan.dt = 0.5;
  std::vector<int> judged;
  std::vector<double> times;
  const cl::FrameLoopResult result =
      cl::run_frame_loop(run.state, run.step(), run.measure(), plan, {}, [&](const cl::FrameEvent& event) {
        judged.push_back(event.frame);
        times.push_back(event.time);
        CHECK(event.problem.empty());
      });
  CHECK(result.frames_done == 7);
  CHECK(result.problem.empty());
  CHECK(result.status == "ok");
  CHECK(judged == std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7});
  CHECK(times.back() == 3.5);
}

TEST_CASE("the energy verdict stops a run that rises above the scale, or only reports it", "[common][frame_loop]") {
  // Kinetic energy after step f: ½ f². Scale 10 J: first exceeded at f = 5 (12.5 J).
  cl::FramePlan plan;
  plan.frames = 20;
  plan.dt = 1.0;
  plan.energy_scale = 10.0;

  SECTION("kStop: the run stops at the first frame above the scale") {
    Kicked run;
    const cl::FrameLoopResult result = cl::run_frame_loop(run.state, run.step(), run.measure(), plan);
    CHECK(result.problem_frame == 5);
    CHECK(result.frames_done == 5);
    CHECK_THAT(result.problem, StartsWith("total energy rose 12.5 J"));
    CHECK(result.status == "diverged: " + result.problem);
    CHECK(result.energy_exceeded_frame == -1);
  }
  SECTION("kReport: the run goes on, the first frame above the scale is noted once") {
    Kicked run;
    plan.energy_verdict = cl::EnergyVerdict::kReport;
    const cl::FrameLoopResult result = cl::run_frame_loop(run.state, run.step(), run.measure(), plan);
    CHECK(result.problem.empty());
    CHECK(result.frames_done == 20);
    CHECK(result.energy_exceeded_frame == 5);
    CHECK_THAT(result.energy_exceeded, ContainsText("12.5 J") && ContainsText("10 J"));
    CHECK(result.max_energy_rise == 0.5 * 20 * 20);
  }
  SECTION("kOff: nothing is said") {
    Kicked run;
    plan.energy_verdict = cl::EnergyVerdict::kOff;
    const cl::FrameLoopResult result = cl::run_frame_loop(run.state, run.step(), run.measure(), plan);
    CHECK(result.problem.empty());
    CHECK(result.energy_exceeded_frame == -1);
  }
}

TEST_CASE("a frame's verdict: the state's health first, then the lab's own problem, then the energy",
          "[common][frame_loop]") {
  cl::FramePlan plan;
  plan.frames = 10;
  plan.dt = 1.0;
  plan.energy_scale = 1e-3;
  // From frame 3 on: positions NaN, a problem of the lab's own and an energy rise, all at once.
  auto run_with = [&](bool nan, const std::string& own, double energy) {
    cl::Particles state = one_particle();
    const cl::StepFunction step = [&](int f) {
      if (f == 3 && nan) state.x(1, 0) = NAN;
      return cl::StepVerdict{};
    };
    const cl::MeasureFunction measure = [&](int f, double) {
      return cl::FrameMeasure{{}, f >= 3 ? energy : 0.0, {}, {}, f >= 3 ? own : std::string()};
    };
    return cl::run_frame_loop(state, step, measure, plan);
  };
  cl::FrameLoopResult result = run_with(true, "the lab's own problem", 1.0);
  CHECK(result.problem_frame == 3);
  CHECK(result.problem == "positions are not finite");
  result = run_with(false, "the lab's own problem", 1.0);
  CHECK(result.problem == "the lab's own problem");
  result = run_with(false, "", 1.0);
  CHECK_THAT(result.problem, StartsWith("total energy rose 1 J"));
  result = run_with(false, "", 1e-4);
  CHECK(result.problem.empty());
  CHECK(result.frames_done == 10);
}

TEST_CASE("a step that could not be taken stops the run, is not counted, and keeps its own status",
          "[common][frame_loop]") {
  Kicked run;
  run.kick = 0.0;
  const cl::FramePlan plan = cl::frame_plan(10, 0.1, 0.0);
  const cl::test::ScratchDir scratch("frame_loop_failed_step");
  cl::FrameOutput output = history_in(scratch, "per_frame.csv");
  output.columns = {"speed"};
  const cl::FrameLoopResult result = cl::run_frame_loop(
      run.state,
      [](int f) { return f == 4 ? cl::StepVerdict{"singular: J is rank deficient", false} : cl::StepVerdict{}; },
      run.measure(), plan, output);
  CHECK(result.frames_done == 3);
  CHECK(result.step_failed);
  CHECK(result.problem_frame == 4);
  CHECK(result.status == "singular: J is rank deficient");
  const std::vector<std::string> lines = lines_of(output.csv_path);
  REQUIRE(lines.size() == 6);  // the header, frames 0-3, the failed frame 4
  CHECK(lines[0] == "frame,time,speed,status");
  CHECK_THAT(lines[1], StartsWith("0,0,") && ContainsText(",ok"));
  CHECK_THAT(lines[5], StartsWith("4,") && ContainsText("singular: J is rank deficient"));
}

TEST_CASE("a step's own problem is prefixed in the history and the loop's clock or the step's seconds is kept",
          "[common][frame_loop]") {
  Kicked run;
  run.kick = 0.0;
  const cl::FramePlan plan = cl::frame_plan(5, 1.0, 0.0);
  const cl::test::ScratchDir scratch("frame_loop_step_problem");
  cl::FrameOutput output = history_in(scratch, "per_step.csv");
  output.index_column = "step";
  output.problem_prefix = "unstable: ";
  const cl::FrameLoopResult result = cl::run_frame_loop(
      run.state, [](int f) { return cl::StepVerdict{f == 2 ? "no decrease" : "", true, 0.25}; },
      [](int, double) { return cl::FrameMeasure{}; }, plan, output);
  CHECK(result.frames_done == 2);
  CHECK(result.problem == "no decrease");
  CHECK(result.seconds == 0.5);
  const std::vector<std::string> lines = lines_of(output.csv_path);
  REQUIRE(lines.size() == 4);
  CHECK(lines[0] == "step,time,status");
  CHECK(lines[3] == "2,2,unstable: no decrease");
}

TEST_CASE("settle windows: a constant measure settles after three windows, not before the given frame",
          "[common][frame_loop]") {
  Kicked run;
  run.kick = 0.0;
  cl::FramePlan plan;
  plan.frames = 1000;
  plan.dt = 1.0;
  plan.window_frames = 10;
  plan.settle_tolerance = 1e-9;
  cl::FrameLoopResult result = cl::run_frame_loop(run.state, run.step(), run.measure(), plan);
  CHECK(result.settled);
  CHECK(result.frames_done == 30);
  CHECK(result.windows_done == 3);
  CHECK(result.window_means == std::vector<double>{1.0});
  CHECK(result.previous_window_means == std::vector<double>{1.0});
  CHECK(result.window_spread == 0.0);

  plan.settle_not_before = 55;
  result = cl::run_frame_loop(run.state, run.step(), run.measure(), plan);
  CHECK(result.frames_done == 60);

  plan.window_frames = 0;  // no windows: all frames
  result = cl::run_frame_loop(run.state, run.step(), run.measure(), plan);
  CHECK_FALSE(result.settled);
  CHECK(result.frames_done == 1000);
  CHECK(result.windows_done == 0);
}

TEST_CASE("the frame loop refuses a negative frame count or window and a NaN tolerance", "[common][frame_loop]") {
  Kicked run;
  cl::FramePlan plan;
  plan.frames = -1;
  CHECK_THROWS_AS(cl::run_frame_loop(run.state, run.step(), run.measure(), plan), std::invalid_argument);
  plan.frames = 1;
  plan.window_frames = -1;
  CHECK_THROWS_AS(cl::run_frame_loop(run.state, run.step(), run.measure(), plan), std::invalid_argument);
  plan.window_frames = 1;
  plan.settle_tolerance = NAN;
  CHECK_THROWS_AS(cl::run_frame_loop(run.state, run.step(), run.measure(), plan), std::invalid_argument);
}
