// Graded tests for lab07.5 (with the whole step): what a step at C = 0
// guarantees, a bead hanging at rest, and the period of a rigid pendulum.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "scenes_for_tests.h"
#include "step.h"
#include "tests/support/checks.h"

using cl::lab07::Method;
using Eigen::Vector3d;

namespace {

constexpr double kPi = 3.14159265358979323846;

const char* name_of(Method method) { return method == Method::kKkt ? "kkt" : "schur"; }

}  // namespace

TEST_CASE("with C = 0 a step meets the linearised constraint phi + dt J v_new = 0 to 1e-10", "[lab07][pts=1]") {
  // The second block row at C = 0 is ΔtJv_new = −φ. Checked here with φ and
  // J·v written out in the test: φ_e = ‖d‖ − L, (Jv)_e = n·(v_i − v_j),
  // evaluated at the positions BEFORE the step, v = 0 for pinned particles.
  for (const Method method : {Method::kKkt, Method::kSchur}) {
    for (std::uint64_t seed = 200; seed < 206; ++seed) {
      std::mt19937_64 rng(seed);
      const lab07_test::RandomScene scene = lab07_test::random_scene(rng, 15, 2, 0);
      cl::lab07::StepSettings settings;
      settings.dt = seed % 2 == 0 ? 1.0 / 60.0 : 0.2;
      settings.method = method;
      CAPTURE(name_of(method), seed, settings.dt, scene.text);
      cl::Particles particles = scene.particles;
      const cl::lab07::StepResult result = cl::lab07::constrained_step(particles, scene.springs, settings);
      REQUIRE(cl::test::solved(result));
      double worst = 0.0;
      std::size_t worst_spring = 0;
      for (std::size_t e = 0; e < scene.springs.size(); ++e) {
        const cl::Spring& s = scene.springs[e];
        if (!std::isfinite(s.stiffness)) {  // the hard ones: C_e = 0
          const Vector3d d = scene.particles.x.col(s.i) - scene.particles.x.col(s.j);
          const double phi = d.norm() - s.rest_length;
          const double jv = d.normalized().dot(particles.v.col(s.i) - particles.v.col(s.j));
          if (!(std::abs(phi + settings.dt * jv) <= worst)) {
            worst = std::abs(phi + settings.dt * jv);
            worst_spring = e;
          }
        }
      }
      CAPTURE(worst_spring);
      REQUIRE(cl::test::near(worst, 0.0, 1e-10, "phi + dt J v_new of spring " + std::to_string(worst_spring)));
    }
  }
}

TEST_CASE("a bead hanging at rest has lambda = -m g and stays at rest", "[lab07][pts=1]") {
  // At rest φ = 0 and v = 0; the Schur equation gives Δt² w λ = −Δt² n·g with
  // n = −ŷ the link's direction from pin to bead, so λ = −m g (tension, N),
  // and v_new = Δt g + Δt w n λ = 0. With a spring of stiffness k already
  // stretched by its static sag m g / k, the same holds.
  for (const Method method : {Method::kKkt, Method::kSchur}) {
    for (const double m : {0.001, 2.0, 500.0}) {
      for (const double k : {cl::kInfiniteStiffness, 50.0, 1e7}) {
        const double g = 9.81, length = 0.7;
        const double sag = std::isfinite(k) ? m * g / k : 0.0;
        cl::Particles particles;
        particles.x.resize(3, 2);
        particles.x.col(0).setZero();
        particles.x.col(1) = Vector3d(0.0, -(length + sag), 0.0);
        particles.v.setZero(3, 2);
        particles.inv_mass.resize(2);
        particles.inv_mass << 0.0, 1.0 / m;
        cl::lab07::StepSettings settings;
        settings.gravity = Vector3d(0.0, -g, 0.0);
        settings.method = method;
        CAPTURE(name_of(method), m, k, sag);
        for (int step = 1; step <= 3; ++step) {
          const cl::lab07::StepResult result =
              cl::lab07::constrained_step(particles, {cl::Spring{0, 1, length, k}}, settings);
          CAPTURE(step);
          REQUIRE(cl::test::solved(result));
          REQUIRE(result.lambda.size() == 1);
          CHECK(cl::test::near_rel(result.lambda[0], -m * g, 1e-9));
          CHECK(cl::test::near(particles.v.col(1).norm(), 0.0, 1e-9));
        }
      }
    }
  }
}

TEST_CASE("a rigid pendulum with small dt swings with period 2 pi sqrt(L/g)(1 + theta0^2/16) within 1e-3",
          "[lab07][pts=1]") {
  // Implicit Euler damps the swing by about exp(−(g/L)Δt t/2) and changes the
  // period by O((ωΔt)²); with Δt = 1 ms over three periods both effects are
  // far below 1e-3 (so is the series' next term, 11θ0⁴/3072 = 3e-5 at 0.3).
  const double g = 9.81, length = 0.8, dt = 1e-3;
  for (const double theta0 : {0.1, 0.3}) {
    cl::Particles particles;
    particles.x.resize(3, 2);
    particles.x.col(0).setZero();
    particles.x.col(1) = length * Vector3d(std::sin(theta0), -std::cos(theta0), 0.0);
    particles.v.setZero(3, 2);
    particles.inv_mass.resize(2);
    particles.inv_mass << 0.0, 1.0;
    const std::vector<cl::Spring> link = {cl::Spring{0, 1, length, cl::kInfiniteStiffness}};
    cl::lab07::StepSettings settings;
    settings.dt = dt;
    settings.gravity = Vector3d(0.0, -g, 0.0);
    const cl::MovableMap map = cl::make_movable_map(particles.inv_mass);
    const double expected = 2.0 * kPi * std::sqrt(length / g) * (1.0 + theta0 * theta0 / 16.0);
    std::vector<double> crossings;
    const long steps = std::lround(3.2 * expected / dt);
    for (long k = 0; k < steps; ++k) {
      const double before = particles.x(0, 1);
      const cl::lab07::StepResult result = cl::lab07::constrained_step(particles, link, map, settings);
      REQUIRE(cl::test::solved(result));
      const double after = particles.x(0, 1);
      if ((before > 0.0) != (after > 0.0)) {
        crossings.push_back(dt * (static_cast<double>(k) + before / (before - after)));
      }
    }
    REQUIRE(crossings.size() >= 6);
    const double measured =
        2.0 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
    CAPTURE(theta0, crossings.size(), measured, expected);
    REQUIRE(cl::test::near_rel(measured, expected, 1e-3));
  }
}
