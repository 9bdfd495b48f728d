// The cloth-grid hierarchy of common/hierarchy.h (lab 10): which lines each
// level keeps, the parents and weights, the masses, the coarse constraints.
#include <algorithm>
#include <set>
#include <stdexcept>
#include <string>

#include "tests/support/catch.h"

#include "common/hierarchy.h"
#include "common/scene.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

cl::Scene grid(int nx, int ny, const std::string& pins) {
  return cl::parse_scene(R"({"cloth": {"nx": )" + std::to_string(nx) + R"(, "ny": )" + std::to_string(ny) +
                             R"(, "width": 1.5, "height": 0.8, "mass": 2, "pin": [)" + pins + "]}}",
                         "hierarchy-grid");
}

cl::ClothHierarchy build(const cl::Scene& scene, int levels) {
  return cl::build_cloth_hierarchy(scene.grid_nx, scene.grid_ny, scene.particles.x, scene.particles.inv_mass,
                                   scene.springs, levels);
}

}  // namespace

TEST_CASE("coarser lines keep every other line and the last", "[common][hierarchy]") {
  CHECK(cl::coarser_lines(3) == std::vector<int>{0, 2});
  CHECK(cl::coarser_lines(4) == std::vector<int>{0, 2, 3});
  CHECK(cl::coarser_lines(5) == std::vector<int>{0, 2, 4});
  const std::vector<int> kept = cl::coarser_lines(64);
  CHECK(kept.size() == 33);
  CHECK(kept[31] == 62);
  CHECK(kept[32] == 63);
  CHECK_THROWS_AS(cl::coarser_lines(2), std::invalid_argument);
  CHECK(cl::max_levels(2, 9) == 1);
  CHECK(cl::max_levels(3, 3) == 2);
  CHECK(cl::max_levels(64, 64) == 7);  // 64, 33, 17, 9, 5, 3, 2
  CHECK(cl::max_levels(64, 5) == 3);   // rows 5, 3, 2
}

TEST_CASE("every finer particle off the coarse level has 1 to 4 parents with weights summing to 1",
          "[common][hierarchy]") {
  for (const auto& [nx, ny] : {std::pair<int, int>{9, 9}, {8, 13}, {32, 32}, {5, 3}}) {
    const cl::Scene scene = grid(nx, ny, R"("top-left", "top-right")");
    const int levels = cl::max_levels(nx, ny);
    const cl::ClothHierarchy hierarchy = build(scene, levels);
    REQUIRE(hierarchy.level_count() == levels);
    CHECK(hierarchy.levels.back().prolongation.empty());
    for (int l = 0; l + 1 < levels; ++l) {
      const cl::HierarchyLevel& fine = hierarchy.levels[static_cast<std::size_t>(l)];
      const cl::HierarchyLevel& coarse = hierarchy.levels[static_cast<std::size_t>(l + 1)];
      CAPTURE(nx, ny, l);
      CHECK(static_cast<int>(coarse.particles.size()) == coarse.nx * coarse.ny);
      CHECK(coarse.columns.front() == 0);
      CHECK(coarse.columns.back() == nx - 1);
      CHECK(coarse.rows.back() == ny - 1);
      const std::set<int> on_coarse(coarse.particles.begin(), coarse.particles.end());
      std::set<int> covered(on_coarse);
      for (const cl::Interpolation& e : fine.prolongation) {
        CAPTURE(e.particle);
        CHECK(on_coarse.count(e.particle) == 0);
        CHECK(covered.insert(e.particle).second);  // listed once
        REQUIRE(e.parents.size() == e.weights.size());
        CHECK((e.parents.size() == 1 || e.parents.size() == 2 || e.parents.size() == 4));
        double sum = 0.0;
        Eigen::Vector3d interpolated = Eigen::Vector3d::Zero();
        for (std::size_t k = 0; k < e.parents.size(); ++k) {
          CHECK(on_coarse.count(e.parents[k]) == 1);
          CHECK(e.weights[k] > 0.0);
          sum += e.weights[k];
          interpolated += e.weights[k] * scene.particles.x.col(e.parents[k]);
        }
        CHECK_THAT(sum, WithinAbs(1.0, 1e-15));
        // Bilinear weights reproduce the flat rest grid.
        CHECK_THAT((interpolated - scene.particles.x.col(e.particle)).norm(), WithinAbs(0.0, 1e-14));
      }
      CHECK(covered == std::set<int>(fine.particles.begin(), fine.particles.end()));
    }
  }
}

TEST_CASE("coarse masses add up to the cloth's and pinned particles stay pinned", "[common][hierarchy]") {
  const cl::Scene free_cloth = grid(14, 11, "");
  const cl::ClothHierarchy hierarchy = build(free_cloth, 4);
  for (const cl::HierarchyLevel& level : hierarchy.levels) {
    double mass = 0.0;
    for (const int p : level.particles) mass += 1.0 / level.inv_mass[p];
    CHECK_THAT(mass, WithinRel(2.0, 1e-13));
    for (Eigen::Index p = 0; p < level.inv_mass.size(); ++p) {
      if (std::find(level.particles.begin(), level.particles.end(), static_cast<int>(p)) == level.particles.end()) {
        CHECK(level.inv_mass[p] == 0.0);  // not on this level
      }
    }
  }
  const cl::Scene pinned = grid(14, 11, R"("top")");
  for (const cl::HierarchyLevel& level : build(pinned, 4).levels) {
    for (const int p : level.particles) {
      CAPTURE(p);
      CHECK((level.inv_mass[p] == 0.0) == (pinned.particles.inv_mass[p] == 0.0));
    }
  }
}

TEST_CASE("coarse constraints are the level grid's structural and shear edges at rest length", "[common][hierarchy]") {
  const cl::Scene scene = grid(12, 9, R"("top-left")");
  const cl::ClothHierarchy hierarchy = build(scene, 3);
  CHECK(hierarchy.levels[0].springs.size() == scene.springs.size());
  for (int l = 1; l < 3; ++l) {
    const cl::HierarchyLevel& level = hierarchy.levels[static_cast<std::size_t>(l)];
    const std::size_t nx = static_cast<std::size_t>(level.nx), ny = static_cast<std::size_t>(level.ny);
    CHECK(level.springs.size() == (nx - 1) * ny + nx * (ny - 1) + 2 * (nx - 1) * (ny - 1));
    for (const cl::Spring& s : level.springs) {
      CHECK(s.rest_length == (scene.particles.x.col(s.i) - scene.particles.x.col(s.j)).norm());
      CHECK(s.rest_length > 0.0);
    }
  }
}

TEST_CASE("the hierarchy builder rejects bad input", "[common][hierarchy]") {
  const cl::Scene scene = grid(6, 6, "");
  const Eigen::Matrix3Xd& x = scene.particles.x;
  const Eigen::VectorXd& w = scene.particles.inv_mass;
  CHECK_THROWS_AS(cl::build_cloth_hierarchy(6, 6, x, w, scene.springs, 0), std::invalid_argument);
  CHECK_THROWS_AS(cl::build_cloth_hierarchy(6, 6, x, w, scene.springs, cl::max_levels(6, 6) + 1),
                  std::invalid_argument);
  CHECK_THROWS_AS(cl::build_cloth_hierarchy(6, 5, x, w, scene.springs, 2), std::invalid_argument);
  CHECK_THROWS_AS(cl::build_cloth_hierarchy(1, 36, x, w, scene.springs, 1), std::invalid_argument);
  Eigen::VectorXd negative = w;
  negative[3] = -1.0;
  CHECK_THROWS_AS(cl::build_cloth_hierarchy(6, 6, x, negative, scene.springs, 2), std::invalid_argument);
  CHECK_THROWS_AS(cl::build_cloth_hierarchy(6, 6, x, w.head(30), scene.springs, 2), std::invalid_argument);
}
