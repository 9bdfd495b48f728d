// Hidden graded test: a step with contact commutes with a rotation of the
// whole scene (positions, velocities, gravity, colliders).
#include <cmath>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "contact_step.h"
#include "lab14_scenes.h"
#include "tests/support/checks.h"

TEST_CASE("a step with contact commutes with a rotation", "[lab14][pts=1][hidden]") {
  using namespace lab14_test;
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, -0.5).normalized()).matrix();
  for (const cl::lab14::Method method : kMethods) {
    CAPTURE(cl::lab14::method_name(method));
    cl::Scene plain = flat_cloth(6, 0.0, 1e3);
    plain.particles.v.row(1).setConstant(-1.0);
    plain.colliders.push_back(sphere(Eigen::Vector3d(0.1, -0.1, 0.4), 0.2, 0.4));
    plain.colliders.push_back(capsule(Eigen::Vector3d(-0.5, -0.05, 0.8), Eigen::Vector3d(0.5, -0.1, 0.9), 0.05, 0.2));
    cl::Scene turned = plain;
    turned.particles.x = rotation * plain.particles.x;
    turned.particles.v = rotation * plain.particles.v;
    for (cl::Collider& collider : turned.colliders) {
      collider.a = rotation * collider.a;
      collider.b = rotation * collider.b;
      collider.normal = rotation * collider.normal;
    }
    cl::lab14::StepSettings settings = settings_for(method, 20);
    cl::lab14::ContactStepper a(plain, settings);
    settings.gravity = rotation * settings.gravity;
    cl::lab14::ContactStepper b(turned, settings);
    for (int step = 0; step < 3; ++step) {
      const cl::lab14::StepReport first = a.step(plain.particles);
      const cl::lab14::StepReport second = b.step(turned.particles);
      REQUIRE(first.contacts.size() == second.contacts.size());
    }
    CHECK(cl::test::near(Eigen::Matrix3Xd(rotation * plain.particles.x), turned.particles.x, 1e-9, "particle"));
  }
}
