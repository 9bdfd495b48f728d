// The steps of every method (given code on the student's functions): a particle
// resting on a plane, one above it, and one moving away from it.
#include <cmath>

#include "tests/support/catch.h"

#include "contact_step.h"
#include "lab14_scenes.h"
#include "tests/support/checks.h"

TEST_CASE("a particle resting on a plane stays on it and the constrained force is its weight", "[lab14][pts=2]") {
  using namespace lab14_test;
  for (const cl::lab14::Method method : kMethods) {
    CAPTURE(cl::lab14::method_name(method));
    const double mass = 0.25;
    cl::Scene scene = particle(Eigen::Vector3d(0.3, 0.0, -0.7), Eigen::Vector3d::Zero(), mass);
    scene.colliders.push_back(plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 0.5));
    cl::lab14::ContactStepper stepper(scene, settings_for(method));
    for (int step = 0; step < 5; ++step) {
      CAPTURE(step);
      const cl::lab14::StepReport report = stepper.step(scene.particles);
      REQUIRE(report.contacts.size() == 1);
      CHECK(cl::test::at_most("penetration (m)", -scene.particles.x(1, 0), 1e-9));
      CHECK(cl::test::near(scene.particles.v.col(0), Eigen::Vector3d::Zero(), 1e-12, "velocity"));
      if (method == cl::lab14::Method::kConstrained) {
        // The impulse over the step, λ_n Δt = m g Δt, to 1e-9 relative.
        CHECK(cl::test::near_rel(report.multipliers[0].normal * kDt, mass * kG * kDt, 1e-9, "λ_n Δt (N s)"));
      }
    }
  }
}

TEST_CASE("a particle above a plane or moving away from it is not touched", "[lab14][pts=2]") {
  using namespace lab14_test;
  for (const cl::lab14::Method method : kMethods) {
    CAPTURE(cl::lab14::method_name(method));
    // Above: free fall, x = x0 + Δt(v0 + Δt g) (symplectic Euler), as without
    // colliders (to 1e-13: PBD's v = (p − x)/Δt rounds).
    cl::Scene scene = particle(Eigen::Vector3d(0.0, 0.5, 0.0), Eigen::Vector3d(0.1, 0.0, 0.0));
    scene.colliders.push_back(plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 1.0));
    cl::lab14::ContactStepper stepper(scene, settings_for(method));
    const cl::lab14::StepReport above = stepper.step(scene.particles);
    const Eigen::Vector3d v1(0.1, -kG * kDt, 0.0);
    CHECK(cl::test::near(scene.particles.v.col(0), v1, 1e-13, "velocity above the plane"));
    CHECK(cl::test::near(scene.particles.x.col(0), Eigen::Vector3d(Eigen::Vector3d(0.0, 0.5, 0.0) + kDt * v1), 1e-15,
                         "position above the plane"));
    for (const cl::lab14::ContactMultipliers& lambda : above.multipliers) {
      CHECK(cl::test::near(lambda.normal, 0.0, 0.0, "λ_n of a contact that never touched"));
    }
    // On the plane and moving away fast: no pull, the velocity is the free one.
    cl::Scene away = particle(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.5, 2.0, 0.0));
    away.colliders.push_back(plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 1.0));
    cl::lab14::ContactStepper away_stepper(away, settings_for(method));
    const cl::lab14::StepReport report = away_stepper.step(away.particles);
    CHECK(cl::test::near(away.particles.v.col(0), Eigen::Vector3d(0.5, 2.0 - kG * kDt, 0.0), 1e-13,
                         "velocity moving away"));
    for (const cl::lab14::ContactMultipliers& lambda : report.multipliers) {
      CHECK(cl::test::near(lambda.normal, 0.0, 0.0, "λ_n moving away"));
    }
  }
}
