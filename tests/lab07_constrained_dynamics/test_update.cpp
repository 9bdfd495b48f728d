// Graded tests of lab07.4's and lab07.5's own contracts, called directly with
// inputs written out here (no φ or J of yours, no other solve): the Schur solve
// with no constraint and its refusals, and update_positions on its own. A step
// that moves x with the old velocity, or leaves a pinned particle's velocity,
// runs whole scenes without failing anything else, yet drifts (README.md,
// "Your task").
#include <cmath>
#include <limits>
#include <string>

#include "tests/support/catch.h"

#include "constrained.h"
#include "tests/support/checks.h"

using Eigen::Vector3d;

namespace {

// Three particles, the middle one pinned, each with a velocity of its own
// (a pinned particle's may be anything: a scene, or a pin set mid-run).
cl::Particles three_particles() {
  cl::Particles particles;
  particles.x.resize(3, 3);
  particles.x << 0.0, 1.0, 2.0,  //
      0.5, 0.0, -0.5,            //
      0.0, 0.25, 1.0;
  particles.v.resize(3, 3);
  particles.v << 1.0, 1.0, -2.0,  //
      0.0, 0.0, 3.0,              //
      -1.0, 0.0, 0.5;
  particles.inv_mass.resize(3);
  particles.inv_mass << 2.0, 0.0, 0.5;
  return particles;
}

cl::lab07::LinearizedStep free_step(int unknowns) {
  cl::lab07::LinearizedStep step;
  step.jacobian.resize(0, 3 * unknowns);
  step.phi.resize(0);
  step.inv_mass = Eigen::VectorXd::Constant(3 * unknowns, 4.0);
  step.velocity = Eigen::VectorXd::LinSpaced(3 * unknowns, -1.0, 2.0);
  step.gravity = Vector3d(0.5, -9.81, 0.0);
  step.dt = 0.1;
  return step;
}

}  // namespace

TEST_CASE("update_positions moves x by dt times the new velocity and zeroes a pinned particle's", "[lab07][pts=1]") {
  const double dt = 0.05;
  cl::Particles particles = three_particles();
  const cl::Particles before = particles;
  const cl::MovableMap map = cl::make_movable_map(particles.inv_mass);
  REQUIRE(map.unknowns() == 2);
  Eigen::VectorXd velocity(6);
  velocity << 3.0, -4.0, 0.5, -0.25, 7.0, 1.5;  // particles 0 and 2, unlike their old velocities
  CAPTURE(dt, velocity.transpose());
  cl::lab07::update_positions(particles, map, velocity, dt);
  CHECK(cl::test::near(Vector3d(particles.v.col(0)), Vector3d(velocity.segment<3>(0)), 0.0, "v of particle 0"));
  CHECK(cl::test::near(Vector3d(particles.v.col(2)), Vector3d(velocity.segment<3>(3)), 0.0, "v of particle 2"));
  CHECK(cl::test::near(Vector3d(particles.v.col(1)), Vector3d::Zero(), 0.0, "v of pinned particle 1"));
  CHECK(cl::test::near(Vector3d(particles.x.col(0)), Vector3d(before.x.col(0) + dt * velocity.segment<3>(0)), 1e-15,
                       "x of particle 0 (x + dt v_new)"));
  CHECK(cl::test::near(Vector3d(particles.x.col(2)), Vector3d(before.x.col(2) + dt * velocity.segment<3>(3)), 1e-15,
                       "x of particle 2 (x + dt v_new)"));
  CHECK(cl::test::near(Vector3d(particles.x.col(1)), Vector3d(before.x.col(1)), 0.0, "x of pinned particle 1"));

  // Refusals change nothing: a velocity of 3u + 3 entries, and a bad dt.
  for (const double bad_dt : {dt, 0.0, -dt, std::numeric_limits<double>::quiet_NaN()}) {
    cl::Particles refused = three_particles();
    const Eigen::VectorXd bad = bad_dt == dt ? Eigen::VectorXd::Ones(9) : velocity;
    CAPTURE(bad_dt, bad.size());
    CHECK_THROWS_AS(cl::lab07::update_positions(refused, map, bad, bad_dt), std::invalid_argument);
    CHECK(cl::test::near(refused.x, before.x, 0.0, "particle (x after a refusal)"));
    CHECK(cl::test::near(refused.v, before.v, 0.0, "particle (v after a refusal)"));
  }
}

TEST_CASE("the Schur solve with no constraint is free fall and refuses a bad dt or inverse mass", "[lab07][pts=1]") {
  const cl::lab07::LinearizedStep step = free_step(3);
  const cl::lab07::StepSolution solution = cl::lab07::solve_schur(step);
  REQUIRE(cl::test::solved(solution));
  const Eigen::VectorXd expected = step.velocity + step.dt * step.gravity.replicate(3, 1);
  CHECK(cl::test::near(solution.velocity, expected, 1e-15, "unknown (v + dt g)"));
  CHECK(solution.lambda.size() == 0);

  for (const double dt : {0.0, -0.1, std::numeric_limits<double>::infinity()}) {
    cl::lab07::LinearizedStep bad = free_step(2);
    bad.dt = dt;
    CAPTURE(dt);
    CHECK_THROWS_AS(cl::lab07::solve_schur(bad), std::invalid_argument);
  }
  for (const double w : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    cl::lab07::LinearizedStep bad = free_step(2);
    bad.inv_mass[4] = w;
    CAPTURE(w);
    CHECK_THROWS_AS(cl::lab07::solve_schur(bad), std::invalid_argument);
  }
}
