// Coulomb's law on an incline of angle θ, every method (README.md, "The
// incline"): at rest it sticks for tan θ <= μ; otherwise it slides with
// a = g (sin θ − μ cos θ). On a plane the position-based friction of
// friction_correction is exact too (its normal correction is g cos θ Δt² per
// step), so every method is held to round-off over 100 steps: 1e-9 relative
// (the constrained method: 1e-6 by the issue, met to 1e-9 here too).
#include <cmath>

#include "tests/support/catch.h"

#include "contact_step.h"
#include "experiments.h"
#include "lab14_scenes.h"
#include "tests/support/checks.h"

namespace {
constexpr double kPiIncline = 3.14159265358979323846;
}

TEST_CASE("incline sticks for tan theta at most mu and slides at g sin theta minus mu g cos theta", "[lab14][pts=3]") {
  using namespace lab14_test;
  for (const cl::lab14::Method method : kMethods) {
    for (const double mu : {0.0, 0.3, 1.0}) {
      for (const double degrees : {10.0, 30.0, 44.0, 60.0}) {
        CAPTURE(cl::lab14::method_name(method), mu, degrees);
        const double theta = degrees * kPiIncline / 180.0;
        cl::Scene scene = cl::lab14::incline_scene(degrees, mu, 100);
        cl::lab14::ContactStepper stepper(scene, settings_for(method));
        for (int step = 0; step < 100; ++step) stepper.step(scene.particles);
        const Eigen::Vector3d down(-std::cos(theta), -std::sin(theta), 0.0);
        const Eigen::Vector3d normal(-std::sin(theta), std::cos(theta), 0.0);
        CHECK(cl::test::near(normal.dot(scene.particles.x.col(0)), 0.0, 1e-12, "height above the incline (m)"));
        if (std::tan(theta) <= mu) {
          CHECK(cl::test::near(scene.particles.x.col(0), Eigen::Vector3d::Zero(), 1e-12, "position of a stuck particle"));
        } else {
          const double a = kG * (std::sin(theta) - mu * std::cos(theta));
          const double t = 100 * kDt;
          CHECK(cl::test::near_rel(scene.particles.v.col(0).dot(down) / t, a, 1e-9, "acceleration down the slope"));
          // Symplectic Euler's distance: a Δt² n(n+1)/2.
          CHECK(cl::test::near_rel(scene.particles.x.col(0).dot(down), a * kDt * kDt * 100 * 101 / 2.0, 1e-9,
                                   "distance down the slope"));
        }
      }
    }
  }
}

TEST_CASE("friction never reverses a velocity", "[lab14][pts=1]") {
  using namespace lab14_test;
  for (const cl::lab14::Method method : kMethods) {
    for (const double speed : {1e-4, 0.05, 3.0}) {
      CAPTURE(cl::lab14::method_name(method), speed);
      cl::Scene scene = particle(Eigen::Vector3d::Zero(), Eigen::Vector3d(speed, 0.0, -0.5 * speed));
      scene.colliders.push_back(plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 2.0));
      cl::lab14::ContactStepper stepper(scene, settings_for(method));
      const Eigen::Vector3d start_direction(1.0, 0.0, -0.5);
      for (int step = 0; step < 20; ++step) {
        stepper.step(scene.particles);
        CHECK(cl::test::at_least("v · (its starting direction)", scene.particles.v.col(0).dot(start_direction), 0.0));
        // Kinetic friction takes μ g Δt off the speed each step, down to 0 (then static).
        const double slowed = std::max(0.0, speed * std::sqrt(1.25) - 2.0 * kG * kDt * (step + 1));
        CHECK(cl::test::near(scene.particles.v.col(0).norm(), slowed, 1e-12, "speed (m/s)"));
      }
    }
  }
}
