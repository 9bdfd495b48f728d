// The swept test (given detect_contacts on the student's surface_distance and
// projections): a particle fast enough to pass through a sphere, or a plane,
// within one step ends the step on the near side.
#include "tests/support/catch.h"

#include "contact_step.h"
#include "lab14_scenes.h"
#include "tests/support/checks.h"

TEST_CASE("a fast particle is caught by the swept test at a sphere and a plane", "[lab14][pts=2]") {
  using namespace lab14_test;
  for (const cl::lab14::Method method : kMethods) {
    CAPTURE(cl::lab14::method_name(method));
    // 60 m/s down: one step of 1/60 s moves it 1 m, straight through a ball of radius 0.2.
    const Eigen::Vector3d centre(0.0, 0.0, 0.0);
    cl::Scene scene = particle(Eigen::Vector3d(0.01, 0.5, 0.0), Eigen::Vector3d(0.0, -60.0, 0.0));
    scene.colliders.push_back(sphere(centre, 0.2, 0.0));
    cl::lab14::ContactStepper stepper(scene, settings_for(method));
    const cl::lab14::StepReport report = stepper.step(scene.particles);
    REQUIRE(report.contacts.size() == 1);
    CHECK(cl::test::answer("contact.swept", report.contacts[0].swept, true, "the end point lies outside the ball"));
    CHECK(cl::test::at_least("y after the step (above the ball's centre)", scene.particles.x(1, 0), 0.0));
    CHECK(cl::test::at_least("distance to the sphere (m)", (scene.particles.x.col(0) - centre).norm() - 0.2, -1e-9));

    cl::Scene floor = particle(Eigen::Vector3d(0.0, 0.5, 0.0), Eigen::Vector3d(1.0, -100.0, 0.0));
    floor.colliders.push_back(plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 0.0));
    cl::lab14::ContactStepper floor_stepper(floor, settings_for(method));
    floor_stepper.step(floor.particles);
    CHECK(cl::test::near(floor.particles.x(1, 0), 0.0, 1e-9, "height after crossing the plane (m)"));
  }
}
