// TODO(lab14.3): position-based Coulomb friction (Macklin et al. 2014, eqs. 24-25).
#include <cmath>
#include <stdexcept>

#include "tests/support/catch.h"

#include "contact.h"
#include "tests/support/checks.h"

TEST_CASE("friction undoes the tangential move inside the cone", "[lab14][pts=2]") {
  const Eigen::Vector3d normal = Eigen::Vector3d(0.0, 3.0, 4.0) / 5.0;
  const Eigen::Vector3d x(0.2, 0.1, -0.3);
  const Eigen::Vector3d tangent(1.0, 0.0, 0.0);
  const double depth = 0.01;
  for (const double mu : {0.5, 1.0, 3.0}) {
    // ‖Δx_t‖ = 0.004 <= μ d = 0.005 … 0.03; a normal part in the move must not count.
    const Eigen::Vector3d p = x + 0.004 * tangent - 0.02 * normal;
    CAPTURE(mu);
    bool stuck = false;
    const Eigen::Vector3d correction = cl::lab14::friction_correction(x, p, 2.0, normal, depth, mu, stuck);
    CHECK(cl::test::near(correction, Eigen::Vector3d(-0.004 * tangent), 1e-16, "correction"));
    CHECK(cl::test::answer("friction_correction(...) stuck", stuck, true, "‖Δx_t‖ <= μ d"));
  }
}

TEST_CASE("kinetic friction shortens the tangential move by mu d and never reverses it", "[lab14][pts=2]") {
  const Eigen::Vector3d normal(0.0, 1.0, 0.0);
  const Eigen::Vector3d x(0.0, 0.0, 0.0);
  const Eigen::Vector3d move(0.03, -0.002, -0.04);  // tangential part (0.03, 0, −0.04), length 0.05
  for (const double mu : {0.0, 0.2, 0.9, 0.999}) {
    const double depth = 0.05;
    CAPTURE(mu);
    bool stuck = true;
    const Eigen::Vector3d correction = cl::lab14::friction_correction(x, x + move, 1.0, normal, depth, mu, stuck);
    const Eigen::Vector3d tangential(0.03, 0.0, -0.04);
    CHECK(cl::test::near(correction, Eigen::Vector3d(-tangential * (mu * depth / 0.05)), 1e-17, "correction"));
    CHECK(cl::test::near(normal.dot(correction), 0.0, 1e-17, "normal part of the correction"));
    CHECK(cl::test::at_least("(move + correction)·move_t (never reversed)", (move + correction).dot(tangential), 0.0));
    CHECK(cl::test::answer("friction_correction(...) stuck", stuck, false, "‖Δx_t‖ > μ d"));
  }
  bool stuck = true;
  CHECK(cl::test::near(cl::lab14::friction_correction(x, x + move, 0.0, normal, 0.05, 5.0, stuck),
                       Eigen::Vector3d::Zero(), 0.0, "pinned"));
  CHECK(cl::test::near(cl::lab14::friction_correction(x, x + move, 1.0, normal, 0.0, 5.0, stuck),
                       Eigen::Vector3d::Zero(), 0.0, "no normal correction"));
  CHECK(cl::test::answer("friction_correction(d = 0) stuck", stuck, false, "no contact force, no static friction"));
  CHECK_THROWS_AS(cl::lab14::friction_correction(x, x + move, 1.0, normal, -0.1, 0.5, stuck), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab14::friction_correction(x, x + move, 1.0, normal, 0.1, -0.5, stuck), std::invalid_argument);
}

TEST_CASE("friction's bound mu d is a length: the same for every mass", "[lab14][pts=1]") {
  // μ d compares two moves (m); the inverse mass has no place in it. A bound
  // weighted by w, μ d w, holds a heavy particle too little and a light one too much.
  const Eigen::Vector3d normal(0.0, 1.0, 0.0);
  const Eigen::Vector3d x(0.1, 0.2, 0.3);
  const Eigen::Vector3d tangent = Eigen::Vector3d(3.0, 0.0, -4.0) / 5.0;
  const double mu = 0.5, depth = 0.02;  // μ d = 0.01 m
  for (const double inv_mass : {1e-3, 0.25, 4.0, 1e3}) {
    CAPTURE(inv_mass);
    bool stuck = false;
    const Eigen::Vector3d inside = x + 0.009 * tangent - 0.003 * normal;  // ‖Δx_t‖ = 0.9 μ d: static
    Eigen::Vector3d correction = cl::lab14::friction_correction(x, inside, inv_mass, normal, depth, mu, stuck);
    CHECK(cl::test::near(correction, Eigen::Vector3d(-0.009 * tangent), 1e-16, "static correction"));
    CHECK(cl::test::answer("friction_correction(‖Δx_t‖ = 0.9 μ d) stuck", stuck, true, "‖Δx_t‖ <= μ d"));
    const Eigen::Vector3d outside = x + 0.011 * tangent - 0.003 * normal;  // ‖Δx_t‖ = 1.1 μ d: kinetic
    correction = cl::lab14::friction_correction(x, outside, inv_mass, normal, depth, mu, stuck);
    CHECK(cl::test::near(correction, Eigen::Vector3d(-0.01 * tangent), 1e-16, "kinetic correction (length μ d)"));
    CHECK(cl::test::answer("friction_correction(‖Δx_t‖ = 1.1 μ d) stuck", stuck, false, "‖Δx_t‖ > μ d"));
  }
}

TEST_CASE("a particle pressed onto the surface with no tangential move is stuck", "[lab14][pts=1]") {
  // Δx_t = 0 <= μ d: the static case, with nothing to undo, for every μ: with
  // μ = 0 the bound μ d is 0 too, and 0 <= 0 (a strict test would take the
  // kinetic branch and divide 0 by 0). The driver's sticking and sliding
  // counts come from `stuck`.
  const Eigen::Vector3d normal(0.0, 1.0, 0.0);  // the tangential part of a move along it is exactly 0
  const Eigen::Vector3d x(0.2, 0.1, -0.3);
  for (const double mu : {0.0, 0.3, 1.0}) {
    CAPTURE(mu);
    bool stuck = false;
    const Eigen::Vector3d correction =
        cl::lab14::friction_correction(x, x - 0.004 * normal, 1.0, normal, 0.004, mu, stuck);
    CHECK(cl::test::near(correction, Eigen::Vector3d::Zero(), 0.0, "correction"));
    CHECK(cl::test::answer("friction_correction(Δx_t = 0, d > 0) stuck", stuck, true, "0 <= μ d"));
  }
}

TEST_CASE("a particle not pressed onto the surface is never stuck", "[lab14][pts=1]") {
  // d = 0: no normal correction, so no normal force and no static friction,
  // even when nothing moves along the surface (Δx_t = 0 <= μ d = 0 would
  // otherwise count it as stuck). The same for a pinned particle (w = 0).
  const Eigen::Vector3d normal = Eigen::Vector3d(0.0, 3.0, 4.0) / 5.0;
  const Eigen::Vector3d x(0.2, 0.1, -0.3);
  for (const double mu : {0.0, 0.3, 1.0}) {
    for (const double along_normal : {0.0, 0.01}) {
      CAPTURE(mu, along_normal);
      bool stuck = true;
      const Eigen::Vector3d correction =
          cl::lab14::friction_correction(x, x + along_normal * normal, 1.0, normal, 0.0, mu, stuck);
      CHECK(cl::test::near(correction, Eigen::Vector3d::Zero(), 0.0, "correction"));
      CHECK(cl::test::answer("friction_correction(Δx_t = 0, d = 0) stuck", stuck, false, "d = 0: nothing presses"));
      stuck = true;
      cl::lab14::friction_correction(x, x - along_normal * normal, 0.0, normal, 0.004, mu, stuck);
      CHECK(cl::test::answer("friction_correction(Δx_t = 0, w = 0) stuck", stuck, false, "a pinned particle"));
    }
  }
}
