// Graded test for lab04.1, pbd_step on the hanging curtain: its stiffness is
// made by the solver, so the steady strain depends on K and on the resolution.
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/scene.h"
#include "pbd.h"
#include "simulation.h"
#include "tests/support/checks.h"

namespace {

// The shipped curtain-N scenes at any resolution: 1 m × 1 m, 1 kg, structural
// and shear constraints, pinned at the two top corners, 0.1 mm jitter.
cl::Scene curtain(int n) {
  const std::string size = std::to_string(n);
  return cl::parse_scene(R"({"name": "curtain", "dt": 0.0166666666666666667,
      "cloth": {"nx": )" + size + R"(, "ny": )" + size + R"(, "pin": ["top-left", "top-right"]},
      "jitter": {"amplitude": 0.0001, "seed": 4}})",
                         "curtain-" + size);
}

// Steady max strain: the mean over a 1 s window once three successive windows
// agree to 2 %, within 30 s.
double steady_max_strain(const cl::Scene& scene, int iterations) {
  cl::Particles particles = scene.particles;
  const cl::lab04::ConstraintSet constraints = cl::lab04::make_constraint_set(particles.size(), scene.springs);
  cl::lab04::PbdSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.iterations = iterations;
  cl::lab04::RunPlan plan;
  plan.frames = 30 * 60;
  plan.window_frames = 60;
  plan.settle_tolerance = 0.02;
  const cl::lab04::RunResult result = cl::lab04::run_frames(particles, constraints, settings, 1, plan);
  CAPTURE(scene.source, iterations, result.frames_done, result.window_spread);
  REQUIRE(cl::test::healthy(result));
  REQUIRE(result.settled);
  return result.window_max_strain;
}

}  // namespace

TEST_CASE("the curtain's steady strain falls as K grows and rises with resolution", "[lab04][pts=2]") {
  const std::vector<int> resolutions{8, 12, 16};
  const std::vector<int> iterations{2, 8, 32};
  std::vector<std::vector<double>> strain(resolutions.size(), std::vector<double>(iterations.size()));
  for (std::size_t r = 0; r < resolutions.size(); ++r) {
    const cl::Scene scene = curtain(resolutions[r]);
    for (std::size_t k = 0; k < iterations.size(); ++k) strain[r][k] = steady_max_strain(scene, iterations[k]);
  }
  for (std::size_t r = 0; r < resolutions.size(); ++r) {
    for (std::size_t k = 0; k < iterations.size(); ++k) {
      CAPTURE(resolutions[r], iterations[k], strain[r][k]);
      if (k > 0) {
        CAPTURE(iterations[k - 1], strain[r][k - 1]);
        REQUIRE(strain[r][k] < strain[r][k - 1]);
      }
      if (r > 0) {
        CAPTURE(resolutions[r - 1], strain[r - 1][k]);
        REQUIRE(strain[r][k] > strain[r - 1][k]);
      }
    }
  }
}
