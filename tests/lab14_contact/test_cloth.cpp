// A 16 x 16 cloth dropped flat on a plane comes to rest with its contact
// forces summing to its weight; dropped on a sphere, no particle is ever
// inside a collider.
#include "tests/support/catch.h"

#include "contact_step.h"
#include "lab14_scenes.h"
#include "tests/support/checks.h"

TEST_CASE("a cloth at rest on a plane is held by contact forces that sum to its weight", "[lab14][pts=2]") {
  using namespace lab14_test;
  cl::Scene scene = flat_cloth(16, 0.05, 1e4);
  scene.colliders.push_back(plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 0.3));
  cl::lab14::ContactStepper stepper(scene, settings_for(cl::lab14::Method::kConstrained));
  cl::lab14::StepReport report;
  for (int step = 0; step < 40; ++step) report = stepper.step(scene.particles);
  REQUIRE(cl::test::healthy(report));
  CHECK(report.contacts.size() == 256);
  // Total mass 1 kg: Σ λ_n n = (0, m g, 0) to 1e-6 relative; nothing sideways.
  CHECK(cl::test::near_rel(report.contact_force.y(), 1.0 * kG, 1e-6, "Σ contact force, y (N)"));
  CHECK(cl::test::near(report.contact_force.x(), 0.0, 1e-6 * kG, "Σ contact force, x (N)"));
  CHECK(cl::test::near(report.contact_force.z(), 0.0, 1e-6 * kG, "Σ contact force, z (N)"));
  CHECK(cl::test::at_most("max |v| (m/s)", scene.particles.v.cwiseAbs().maxCoeff(), 1e-9));
}

TEST_CASE("a cloth dropped on a sphere never has a particle inside a collider", "[lab14][pts=2]") {
  using namespace lab14_test;
  for (const cl::lab14::Method method : kMethods) {
    CAPTURE(cl::lab14::method_name(method));
    cl::Scene scene = flat_cloth(16, 0.0, 1e4);
    scene.colliders.push_back(sphere(Eigen::Vector3d(0.0, -0.3, 0.5), 0.25, 0.3));
    scene.colliders.push_back(plane(Eigen::Vector3d(0.0, -0.6, 0.0), Eigen::Vector3d::UnitY(), 0.3));
    cl::lab14::ContactStepper stepper(scene, settings_for(method));
    double deepest = 0.0;
    int worst_step = -1;
    long long contacts = 0;
    for (int step = 0; step < 90; ++step) {
      const cl::lab14::StepReport report = stepper.step(scene.particles);
      REQUIRE(cl::test::healthy(report));
      contacts += static_cast<long long>(report.contacts.size());
      const double depth = cl::lab14::max_penetration(scene.particles.x, scene.particles.inv_mass, scene.colliders);
      if (depth > deepest) deepest = depth, worst_step = step;
    }
    CAPTURE(worst_step);
    CHECK(cl::test::at_least("contacts over the run", static_cast<double>(contacts), 1.0));
    CHECK(cl::test::at_most("deepest penetration over every step (m)", deepest, 1e-6));
  }
}
