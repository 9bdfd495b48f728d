#pragma once
// The live mode of every time-stepping lab (docs/DESIGN.md §3, "The live
// mode"): `labNN --live [PORT]` steps the scene continuously beside a page in
// the browser, which draws every frame it can take, drags particles, pins
// them and turns the lab's knobs. The loop judges each frame as the frame loop
// does (common/frame_loop.h: the step's own problem, health, the energy
// verdict); a problem pauses the run and the page shows its one line; a frame
// with a non-finite value is never sent. Runs until Ctrl-C, SIGTERM or the
// page's "stop", then writes --summary (when given) and returns 0. The step
// runs on a thread of its own, so a stop is seen during a step of minutes: it
// waits 0.5 s for the step, then writes the summary of the last completed
// step and ends the process with exit 0.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/cli.h"
#include "common/frame_loop.h"
#include "common/live_protocol.h"
#include "common/scene.h"

namespace cl {

struct LiveOptions {
  bool on = false;  // --live given
  int port = 0;     // 0: a free port
};

// Registers `--live [PORT]` (an optional port in [1, 65535]).
void add_live_option(CommandLine& line, LiveOptions& live);

// What a lab gives the live loop.
// What a lab built its solver for in live mode: the inverse masses (pins and
// held particles) and the knobs the solver depends on. A `changed` hook
// rebuilds only when update() says these differ from the last build, so that
// turning a knob the solver does not depend on (K) rebuilds nothing.
class BuiltFor {
 public:
  bool update(const Eigen::VectorXd& inv_mass, std::vector<double> values) {
    if (built_ && inv_mass_.size() == inv_mass.size() && inv_mass_ == inv_mass && values_ == values) return false;
    built_ = true;
    inv_mass_ = inv_mass;
    values_ = std::move(values);
    return true;
  }

 private:
  bool built_ = false;
  Eigen::VectorXd inv_mass_;
  std::vector<double> values_;
};

struct LiveRun {
  LiveRun(std::string lab_name, std::string method_name, Knobs declared)
      : lab(std::move(lab_name)), method(std::move(method_name)), knobs(std::move(declared)) {}
  std::string lab;
  std::string method;
  // The knobs the page turns. A knob named "dt" is the step (s): the loop's
  // clock and the energy verdict's scale use it.
  Knobs knobs;
  // One frame with the knobs' current values, on the scene's particles (their
  // inverse masses say what is pinned or held: read them every step).
  std::function<StepVerdict(const Knobs&)> step;
  // Called before the first step and before the step that follows a change of
  // a knob, a pin or a held particle; it rebuilds what the lab keeps if what
  // that was built for changed (BuiltFor below) and returns what it rebuilt
  // ("A, factored again"), or "" when nothing needed it. The status of that
  // step says so, and its time includes the rebuild. Optional.
  std::function<std::string(const Knobs&)> changed;
  // The energy the verdict watches, J; unset: kinetic + potential in the scene's gravity.
  std::function<double(const Particles&)> energy;
  std::string energy_name = "kinetic + potential energy";
  // false: a rise above the scale is reported once (to the page and stderr)
  // and the run goes on (lab 05's limited runs, as its frame loop does).
  bool energy_stops = true;
};

// Serves the page on 127.0.0.1 (options.port, or a free one), prints its URL
// on one line of stdout, and steps `scene.particles` with run.step until
// stopped. `summary_path` not empty: the run summary of the final state
// (common/summary.h) with live: true, frames and the knobs' values. Throws
// InputError when the page's files are missing or the port cannot be had.
int run_live(Scene& scene, const LiveOptions& options, const LiveRun& run, const std::string& summary_path);

// The page: tools/cl/live_page.html with three.js (tools/cl/vendor/three/), its
// OrbitControls and tools/cl/view_player.js inlined. Throws InputError naming
// a missing file.
std::string live_page();

}  // namespace cl
