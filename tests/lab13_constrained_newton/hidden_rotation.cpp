// Hidden graded test: the step commutes with a rotation of the whole scene
// (positions, velocities, gravity).
#include <cmath>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "iteration.h"
#include "lab13_scenes.h"
#include "tests/support/checks.h"

TEST_CASE("the constrained Newton step commutes with a rotation", "[lab13][pts=1][hidden]") {
  for (const double k : {1e3, 1e7}) {
    CAPTURE(k);
    const cl::Scene scene = lab13_test::curtain(5, k);
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, -0.5).normalized()).matrix();
    cl::lab13::Settings settings;
    settings.iterations = 30;
    settings.tolerance = 1e-12;
    settings.gravity = scene.gravity;
    cl::Particles plain = scene.particles;
    cl::lab13::Solver a(plain.inv_mass, scene.springs, scene.dt);
    REQUIRE(cl::test::healthy(a.step(plain, settings)));
    cl::Particles turned = scene.particles;
    turned.x = rotation * turned.x;
    turned.v = rotation * turned.v;
    settings.gravity = rotation * scene.gravity;
    cl::lab13::Solver b(turned.inv_mass, scene.springs, scene.dt);
    REQUIRE(cl::test::healthy(b.step(turned, settings)));
    CHECK(cl::test::near(Eigen::Matrix3Xd(rotation * plain.x), turned.x, 1e-9, "particle"));
  }
}
