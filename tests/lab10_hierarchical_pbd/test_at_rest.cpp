// Graded test for lab10.3 inside a PBD step (given hpbd_step): pinned particles
// stay pinned on every level, and nothing moves a cloth that is at rest.
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/hierarchy.h"
#include "common/scene.h"
#include "hpbd.h"
#include "simulation.h"
#include "tests/support/checks.h"

using Eigen::Matrix3Xd;

namespace {

cl::Scene cloth(int nx, int ny, const std::string& pins, const std::string& gravity) {
  return cl::parse_scene(R"({"gravity": )" + gravity + R"(, "cloth": {"nx": )" + std::to_string(nx) +
                             R"(, "ny": )" + std::to_string(ny) + R"(, "pin": [)" + pins + "]}}",
                         "test-cloth-" + std::to_string(nx) + "x" + std::to_string(ny));
}

}  // namespace

TEST_CASE("pinned particles never move and a cloth at rest stays at rest", "[lab10][pts=2]") {
  SECTION("at rest, no gravity: every level count leaves the cloth exactly where it is") {
    const cl::Scene scene = cloth(17, 13, R"("top-left", "top-right")", "[0, 0, 0]");
    for (int levels = 1; levels <= cl::max_levels(17, 13); ++levels) {
      const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
          17, 13, scene.particles.x, scene.particles.inv_mass, scene.springs, levels);
      cl::Particles particles = scene.particles;
      cl::lab10::HpbdSettings settings;
      settings.gravity.setZero();
      settings.iterations.assign(static_cast<std::size_t>(levels), 6);
      for (int step = 0; step < 10; ++step) cl::lab10::hpbd_step(particles, hierarchy, settings);
      CAPTURE(levels);
      REQUIRE(cl::test::near(particles.x, scene.particles.x, 1e-15, "particle"));
      REQUIRE(cl::test::near(particles.v.cwiseAbs().maxCoeff(), 0.0, 1e-13));
    }
  }
  SECTION("falling: pinned particles on and off the coarse levels stay exactly put") {
    cl::Scene scene = cloth(33, 33, R"("top-left", "top-right")", "[0, -9.81, 0]");
    std::vector<int> pinned{0, 32};   // the corners: on every level
    pinned.push_back(5 * 33 + 7);     // row 5, column 7: on no coarse level
    pinned.push_back(16 * 33 + 16);   // row 16, column 16: on levels 0 to 4
    for (const int p : pinned) scene.particles.inv_mass[p] = 0.0;
    for (const int levels : {2, 3, 4}) {
      const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
          33, 33, scene.particles.x, scene.particles.inv_mass, scene.springs, levels);
      cl::Particles particles = scene.particles;
      cl::lab10::HpbdSettings settings;
      settings.iterations.assign(static_cast<std::size_t>(levels), 4);
      for (int step = 0; step < 30; ++step) {
        cl::lab10::hpbd_step(particles, hierarchy, settings);
        for (const int p : pinned) {
          CAPTURE(levels, step, p, scene.particles.x.col(p), particles.x.col(p));
          REQUIRE(particles.x.col(p) == scene.particles.x.col(p));
        }
      }
      const double moved = (particles.x - scene.particles.x).cwiseAbs().maxCoeff();
      CAPTURE(levels, moved);
      REQUIRE(moved > 0.01);  // the rest of the cloth did fall
    }
  }
}
