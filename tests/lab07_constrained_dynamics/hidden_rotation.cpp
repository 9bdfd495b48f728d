// Hidden graded test for lab07.4 (run only by the Gradescope bundle, shown to
// the student after grades are published): the Schur solve does not care how
// the scene is turned.
#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "constrained.h"
#include "scenes_for_tests.h"
#include "step.h"
#include "tests/support/checks.h"

TEST_CASE("a Schur solve of a rotated scene is the rotated solve with the same lambda", "[lab07][pts=1][hidden]") {
  // Turn positions, velocities and gravity by R: φ and C are unchanged, J
  // turns with the scene, so v_new turns by R and λ stays what it was.
  for (std::uint64_t seed = 700; seed < 706; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const lab07_test::RandomScene scene = lab07_test::random_scene(rng, 4 + static_cast<int>(seed % 8),
                                                                   static_cast<int>(seed % 2), 3, seed % 3 != 0);
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(2.0 * unit(rng), Eigen::Vector3d(unit(rng), unit(rng), 1.0).normalized()).toRotationMatrix();
    cl::lab07::StepSettings settings;
    settings.dt = seed % 2 == 0 ? 0.05 : 1.0 / 60.0;
    settings.gravity = Eigen::Vector3d(0.4, -9.81, 0.1);
    cl::Particles turned = scene.particles;
    turned.x = rotation * scene.particles.x;
    turned.v = rotation * scene.particles.v;
    cl::lab07::StepSettings turned_settings = settings;
    turned_settings.gravity = rotation * settings.gravity;
    CAPTURE(seed, scene.text, rotation);
    const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
    const cl::lab07::StepSolution plain =
        cl::lab07::solve_schur(cl::lab07::linearize(scene.particles, scene.springs, map, settings));
    const cl::lab07::StepSolution rotated =
        cl::lab07::solve_schur(cl::lab07::linearize(turned, scene.springs, map, turned_settings));
    REQUIRE(cl::test::solved(plain));
    REQUIRE(cl::test::solved(rotated));
    REQUIRE(rotated.velocity.size() == plain.velocity.size());
    const Eigen::Index u = plain.velocity.size() / 3;
    const Eigen::Matrix3Xd expected = rotation * Eigen::Map<const Eigen::Matrix3Xd>(plain.velocity.data(), 3, u);
    const Eigen::Map<const Eigen::Matrix3Xd> actual(rotated.velocity.data(), 3, u);
    const double v_scale = std::max(1.0, plain.velocity.cwiseAbs().maxCoeff());
    REQUIRE(cl::test::near(actual, expected, 1e-9 * v_scale, "unknown"));
    const double lambda_scale = std::max(1.0, plain.lambda.cwiseAbs().maxCoeff());
    REQUIRE(cl::test::near(rotated.lambda, plain.lambda, 1e-9 * lambda_scale, "lambda (one per spring)"));
  }
}
