// Ungraded tests of lab 14's given detection ([lab14_given], run on the
// reference by ctest -L unit): overlapping colliders, a sphere sunk into the
// floor. A particle thrown into the crease where they meet, its move missing
// the sphere and ending below both, must not get a contact on the sphere's
// bottom (a surface point inside the floor's solid, facing the floor's
// contact): with both, a converged constrained step can drive the particle to
// the far tip of the two half-spaces' thin wedge. Also: a particle that starts
// inside a collider is moved out at load (resolve_initial_penetration).
#include "tests/support/catch.h"

#include "common/metrics.h"
#include "contact_step.h"
#include "lab14_scenes.h"
#include "tests/support/checks.h"

namespace crease_test {

using namespace lab14_test;

// The floor y = 0 and a ball of radius 0.2 m whose centre is 0.1 m below it:
// they meet on the circle of radius √0.03 ≈ 0.173 m at y = 0.
const Eigen::Vector3d kCentre(0.0, -0.1, 0.0);
constexpr double kRadius = 0.2;

// Signed distances written here from the shapes' definitions (not the lab's).
double floor_distance(const Eigen::Vector3d& y) { return y.y(); }
double ball_distance(const Eigen::Vector3d& y) { return (y - kCentre).norm() - kRadius; }

// Kinetic + gravity's potential energy (zero at y = 0), as lab 14's loop counts it.
double energy(const cl::Particles& particles) {
  return cl::kinetic_energy(particles) + cl::potential_energy(particles, Eigen::Vector3d(0.0, -kG, 0.0));
}

// A 1 kg particle at (0.4, 0.05, 0), above the floor and outside the ball,
// whose unconstrained step ends at (0.02, −0.6, 0): through the floor outside
// the crease (it passes the ball 7 cm off), 0.3 m below the ball's bottom.
cl::Scene crease() {
  const Eigen::Vector3d start(0.4, 0.05, 0.0), end(0.02, -0.6, 0.0);
  const Eigen::Vector3d velocity = (end - start) / kDt - kDt * Eigen::Vector3d(0.0, -kG, 0.0);
  cl::Scene scene = particle(start, velocity);
  scene.colliders.push_back(plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 0.0));
  scene.colliders.push_back(sphere(kCentre, kRadius, 0.0));
  return scene;
}

}  // namespace crease_test

using namespace crease_test;

TEST_CASE("no contact lies inside another collider: a particle thrown into a sphere-in-floor crease ends outside both",
          "[lab14_given]") {
  for (const cl::lab14::Method method : kMethods) {
    for (const int iterations : {1, 10, 10'000}) {
      CAPTURE(cl::lab14::method_name(method), iterations);
      cl::Scene scene = crease();
      cl::lab14::ContactStepper stepper(scene, settings_for(method, iterations));
      const cl::lab14::StepReport report = stepper.step(scene.particles);
      REQUIRE(report.problem.empty());
      for (const cl::lab14::Contact& contact : report.contacts) {
        CAPTURE(contact.collider);
        // The point of a floor contact may not lie inside the ball, nor a ball contact's inside the floor.
        const double other = contact.collider == 0 ? ball_distance(contact.point) : floor_distance(contact.point);
        CHECK(cl::test::at_least("the contact point's distance to the other collider (m)", other, -1e-9));
      }
      const Eigen::Vector3d y = scene.particles.x.col(0);
      CHECK(y.allFinite());
      CHECK(cl::test::at_least("distance to the floor after the step (m)", floor_distance(y), -1e-9));
      CHECK(cl::test::at_least("distance to the ball after the step (m)", ball_distance(y), -1e-9));
    }
  }
}

TEST_CASE("a converged constrained step into a sphere-in-floor crease does not raise the energy", "[lab14_given]") {
  // μ = 0 and the contacts can only push the particle out: kinetic + potential
  // energy may fall (the step stops the particle's fall) but never rise.
  cl::Scene scene = crease();
  const double before = energy(scene.particles);
  cl::lab14::ContactStepper stepper(scene, settings_for(cl::lab14::Method::kConstrained, 10'000));
  const cl::lab14::StepReport report = stepper.step(scene.particles);
  REQUIRE(report.problem.empty());
  CHECK(cl::test::at_most("kinetic + potential energy after the step (J)", energy(scene.particles), before));
}

TEST_CASE("a particle that starts inside a sphere is moved out at load and gains no kinetic energy",
          "[lab14_given]") {
  using namespace lab14_test;
  // 0.15 m deep in a ball of radius 0.2 m, no gravity: pushed out by the first
  // step's contact it would leave at 0.15 m / Δt = 9 m/s. Moved out at load,
  // it rests on the surface, at rest, for every method.
  for (const cl::lab14::Method method : kMethods) {
    CAPTURE(cl::lab14::method_name(method));
    cl::Scene scene = particle(Eigen::Vector3d(0.05, 0.0, 0.0), Eigen::Vector3d::Zero());
    scene.colliders.push_back(sphere(Eigen::Vector3d::Zero(), 0.2));
    const cl::lab14::InitialPenetration initial =
        cl::lab14::resolve_initial_penetration(scene.particles, scene.colliders);
    CHECK(initial.particles == 1);
    CHECK(cl::test::near(initial.deepest, 0.15, 1e-15, "depth before the move (m)"));
    CHECK(cl::test::near(scene.particles.x.col(0).norm(), 0.2, 1e-15, "distance from the centre after it (m)"));
    cl::lab14::StepSettings settings = settings_for(method);
    settings.gravity.setZero();
    cl::lab14::ContactStepper stepper(scene, settings);
    for (int step = 0; step < 30; ++step) REQUIRE(cl::test::healthy(stepper.step(scene.particles)));
    CHECK(cl::test::at_most("kinetic energy after 30 steps (J)", cl::kinetic_energy(scene.particles), 1e-20));
    CHECK(cl::test::at_most("penetration (m)",
                            cl::lab14::max_penetration(scene.particles.x, scene.particles.inv_mass, scene.colliders),
                            1e-12));
  }
}
