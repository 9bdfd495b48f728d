// Graded test for lab03.1 at the extremes (docs/DESIGN.md §6): degenerate input
// never produces a NaN. (ω ≥ 2, where the iteration itself diverges, is the
// executable's business: it detects and reports it.)
#include <string>
#include <utility>

#include "tests/support/catch.h"

#include "common/scene.h"
#include "jacobi.h"
#include "tests/support/checks.h"

using cl::lab03::Averaging;

namespace {
// `count` sweeps through two buffers that swap, as a driver runs them. x_next
// starts at the right size holding a position no particle has, so a column
// the sweep does not write (a particle with no spring) shows after an odd
// number of sweeps, when the buffer that was never written is the result.
Eigen::Matrix3Xd run(const cl::Scene& scene, int count, double omega, Averaging averaging) {
  const cl::lab03::Incidence incidence = cl::lab03::build_incidence(scene.particles.size(), scene.springs);
  Eigen::Matrix3Xd x = scene.particles.x;
  Eigen::Matrix3Xd x_next = Eigen::Matrix3Xd::Constant(3, x.cols(), 42.0);
  for (int sweep = 0; sweep < count; ++sweep) {
    cl::lab03::jacobi_sweep(x, x_next, scene.particles.inv_mass, scene.springs, incidence, omega, averaging);
    x.swap(x_next);
  }
  return x;
}
}  // namespace

TEST_CASE("lonely and coincident particles and a mass ratio of 1e6 and pinned ends stay finite", "[lab03][pts=1]") {
  // Particle 3 has no spring: it has nothing to average and must stay put,
  // so its column of x_next is a copy of x, written by every sweep.
  // Particles 1 and 2 coincide; the 0-1 and 2-4 springs pull them apart.
  const cl::Scene lonely = cl::parse_scene(R"({"particles": [
      {"x": [0, 0, 0], "pinned": true}, {"x": [0.1, 0.05, 0]}, {"x": [0.1, 0.05, 0]},
      {"x": [5, 5, 5]}, {"x": [0.3, 0, 0], "mass": 1e6}],
      "springs": [{"i": 0, "j": 1, "rest": 0.1}, {"i": 1, "j": 2, "rest": 0.1}, {"i": 2, "j": 4, "rest": 0.1}]})",
                                           "lonely.json");
  const cl::Scene chain = cl::parse_scene(R"({"chain": {"links": 30, "length": 0.1, "pin": "both"},
      "jitter": {"amplitude": 0.01, "seed": 2}})", "chain.json");
  for (const cl::Scene* scene : {&lonely, &chain}) {
    // Summed Jacobi is only stable for small ω (lab README), so it runs at 0.5.
    for (const auto& [omega, averaging] : {std::pair{0.0, Averaging::kByCount}, std::pair{1.0, Averaging::kByCount},
                                           std::pair{1.9, Averaging::kByCount}, std::pair{0.0, Averaging::kNone},
                                           std::pair{0.5, Averaging::kNone}}) {
      {
        CAPTURE(scene->source, omega, averaging == Averaging::kByCount);
        const Eigen::Matrix3Xd x = run(*scene, 10'001, omega, averaging);
        if (scene == &lonely) REQUIRE(cl::test::near(x.col(3), scene->particles.x.col(3), 0.0, "lonely particle 3"));
        REQUIRE(x.allFinite());
        if (omega == 0.0) REQUIRE(cl::test::near(x, scene->particles.x, 0.0, "particle"));
      }
    }
  }
}
