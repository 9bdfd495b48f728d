// Hidden graded test for lab10.3 (run only by the Gradescope bundle, shown to
// the student after grades are published): the coarse-to-fine pass does not
// care where the cloth is in space or how it is turned.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "common/hierarchy.h"
#include "common/scene.h"
#include "hpbd.h"
#include "tests/support/checks.h"

using Eigen::Matrix3Xd;
using Eigen::Vector3d;

TEST_CASE("a hierarchical solve of a rotated and shifted cloth is the rotated and shifted solve",
          "[lab10][pts=1][hidden]") {
  // Unilateral projections depend only on distances and the prolongation adds
  // differences of positions, so for a rotation R and a shift t:
  //     solve(R x + t) = R solve(x) + t   (to round-off).
  // Pinned particles are pinned wherever they are, so both starts keep them.
  std::mt19937_64 rng(1030);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const auto& [nx, ny] : {std::pair<int, int>{9, 9}, {14, 10}}) {
    cl::Scene scene = cl::parse_scene(R"({"cloth": {"nx": )" + std::to_string(nx) + R"(, "ny": )" +
                                          std::to_string(ny) + R"(, "pin": ["top-left", "top-right"]}})",
                                      "hidden-cloth");
    for (Eigen::Index p = 0; p < scene.particles.size(); ++p) {
      if (scene.particles.inv_mass[p] > 0.0) scene.particles.inv_mass[p] = std::pow(10.0, unit(rng));
    }
    const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
        nx, ny, scene.particles.x, scene.particles.inv_mass, scene.springs, 3);
    Matrix3Xd x = 1.2 * scene.particles.x;
    for (Eigen::Index p = 0; p < x.cols(); ++p) x.col(p) += 0.05 * Vector3d(unit(rng), unit(rng), unit(rng));
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(2.5, Vector3d(unit(rng), unit(rng), 1.0).normalized()).toRotationMatrix();
    const Vector3d shift(3.0 * unit(rng), 3.0 * unit(rng), 3.0 * unit(rng));
    Matrix3Xd moved = (rotation * x).colwise() + shift;
    const std::vector<int> iterations{2, 3, 2};
    cl::lab10::solve_hierarchy(x, hierarchy, iterations);
    cl::lab10::solve_hierarchy(moved, hierarchy, iterations);
    const Matrix3Xd expected = (rotation * x).colwise() + shift;
    CAPTURE(nx, ny, iterations, rotation, shift.transpose());
    REQUIRE(cl::test::near(moved, expected, 1e-11, "particle"));
  }
}
