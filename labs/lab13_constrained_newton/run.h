#pragma once
// Lab 13 — given code: one run of a scene, the driver's default mode
// (main.cpp keeps the flags and the dispatch): constrained Newton's steps
// (per_step.csv, iterations.csv, the run summary), lab 06's Newton or PD on
// the same scene for comparison, or with --live either method stepping beside
// a page in the browser (common/live.h; docs/DESIGN.md §3, "The live mode").
#include <string>

#include "common/cli.h"
#include "common/live.h"
#include "experiments.h"

namespace cl::lab13 {

// The live knob k's top (N/m): the stiffness up to which constrained Newton
// converges every step of the curtains (a test holds it: test_step.cpp).
inline constexpr double kLiveStiffnessMax = 1e8;

// The largest dt^2 k (1/m_i + 1/m_j) of a finite spring a run takes with
// constrained Newton (README.md, "Where it holds"): above it the curtains'
// redundant springs make the step's self-stress so stiff that Newton's
// iterates leave the region where it converges, and a run is refused with
// one line naming --stiffness and the range of k at the run's dt. (k = inf is
// the hard step, another problem, and is not bounded.)
inline constexpr double kMaxStiffnessRatio = 1e8;

// Runs --scene (with --stiffness; lab 06's methods refuse hard springs) by
// --method for its steps, or with live.on until the page or a signal stops it:
// knobs K (iterations), dt and k (every spring's stiffness, N/m; none when
// the springs are hard), each change of which builds the solver again.
int run_scene(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, LabOptions lab,
              const LiveOptions& live);

}  // namespace cl::lab13
