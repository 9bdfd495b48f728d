// Graded tests for lab08.2, xpbd_step on hanging springs: the stretch is the
// material's, m g / k per bead carried, whatever Δt is.
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>
#include "tests/support/catch.h"

#include "pbd.h"
#include "tests/support/checks.h"
#include "xpbd.h"

using cl::lab04::ConstraintSet;
using cl::lab08::XpbdSettings;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

// A chain of `beads` particles of mass m below a pin at the origin, hanging
// along the unit vector `down`, springs of rest length L and stiffness k.
// Spring s joins particle s and s+1 and carries the beads s+1 … N, so at rest
// it is stretched by (N − s) m g / k. `at_rest`: start at that equilibrium;
// otherwise at the rest lengths. Velocities zero.
cl::Particles chain(int beads, double mass, double rest_length, double stiffness, double g, const Vector3d& down,
                    bool at_rest) {
  cl::Particles particles;
  particles.x.setZero(3, beads + 1);
  particles.v.setZero(3, beads + 1);
  particles.inv_mass = VectorXd::Constant(beads + 1, 1.0 / mass);
  particles.inv_mass[0] = 0.0;
  double position = 0.0;
  for (int s = 0; s < beads; ++s) {
    position += rest_length + (at_rest ? (beads - s) * mass * g / stiffness : 0.0);
    particles.x.col(s + 1) = position * down;
  }
  return particles;
}

ConstraintSet springs_of(int beads, double rest_length, double stiffness) {
  std::vector<cl::Spring> springs;
  for (int s = 0; s < beads; ++s) springs.push_back({s, s + 1, rest_length, stiffness});
  return cl::lab04::make_constraint_set(beads + 1, springs);
}

double total_stretch(const cl::Particles& particles, double rest_length) {
  double stretch = 0.0;
  for (Eigen::Index s = 0; s + 1 < particles.size(); ++s) {
    stretch += (particles.x.col(s + 1) - particles.x.col(s)).norm() - rest_length;
  }
  return stretch;
}

// The slowest natural frequency of the vertical chain, ω² = the smallest
// eigenvalue of (k/m)·T, T the chain's tridiagonal matrix (2 on the diagonal,
// 1 in the last entry for the free end, −1 beside it).
double slowest_frequency(int beads, double mass, double stiffness) {
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(beads, beads);
  for (int b = 0; b < beads; ++b) {
    t(b, b) = b + 1 < beads ? 2.0 : 1.0;
    if (b + 1 < beads) t(b, b + 1) = t(b + 1, b) = -1.0;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(t);
  return std::sqrt(stiffness / mass * eigen.eigenvalues().minCoeff());
}

}  // namespace

TEST_CASE("a single hanging spring settles at stretch mg over k for any dt and any K", "[lab08][pts=2]") {
  const double rest_length = 0.8;
  const Vector3d gravity(0.3, -9.81, 1.2);  // tilted on purpose: the spring hangs along g
  const double g = gravity.norm();
  const Vector3d down = gravity / g;

  SECTION("started at the stretch mg/k at rest, one step leaves it there") {
    // One spring converges in one sweep (xpbd.h), so the step is the converged
    // implicit step, whose fixed point at rest is C = −α̃λ with λ = −m g Δt²:
    // k C = m g exactly. Only round-off remains, of the size of the positions
    // and of the Δt² g of the prediction.
    for (const double dt : {1e-6, 1e-3, 1.0 / 60.0, 0.5, 5.0}) {
      for (const int iterations : {1, 2, 7, 100}) {
        for (const double stiffness : {1.0, 100.0, 1e6}) {
          for (const double mass : {0.01, 1.0, 100.0}) {
            cl::Particles particles = chain(1, mass, rest_length, stiffness, g, down, true);
            const ConstraintSet constraints = springs_of(1, rest_length, stiffness);
            const Vector3d expected = particles.x.col(1);
            XpbdSettings settings;
            settings.dt = dt;
            settings.gravity = gravity;
            settings.iterations = iterations;
            VectorXd lambda;
            cl::lab08::xpbd_step(particles, constraints, settings, lambda);
            const double scale = 1e-13 * (expected.norm() + dt * dt * g);
            CAPTURE(dt, iterations, stiffness, mass, expected.transpose(), particles.x.col(1).transpose(),
                    particles.v.col(1).transpose(), lambda);
            REQUIRE(cl::test::near(particles.x.col(1), expected, scale));
            REQUIRE(cl::test::near(particles.v.col(1).norm(), 0.0, scale / dt));
            // λ/Δt² is the spring's force: minus the weight it carries. C = ℓ − L
            // loses about 1e-16·L/C of relative accuracy to cancellation.
            REQUIRE(lambda.size() == 1);
            REQUIRE(cl::test::near_rel(lambda[0] / (dt * dt), -mass * g, 1e-6));
          }
        }
      }
    }
  }

  SECTION("released at its rest length, it settles at mg/k") {
    // With one spring the step is backward Euler for the linear oscillator
    // ω² = k/m (the motion stays on the line of g): every step multiplies the
    // distance from equilibrium, measured in (x, v/ω), by exactly
    // 1/√(1 + ω²Δt²). Run until that has shrunk it by 1e-12; compare to 1e-9.
    const double mass = 1.0, stiffness = 100.0;
    const double omega = std::sqrt(stiffness / mass);
    for (const double dt : {1.0 / 60.0, 0.1, 0.5}) {
      for (const int iterations : {1, 3}) {
        cl::Particles particles = chain(1, mass, rest_length, stiffness, g, down, false);
        const ConstraintSet constraints = springs_of(1, rest_length, stiffness);
        XpbdSettings settings;
        settings.dt = dt;
        settings.gravity = gravity;
        settings.iterations = iterations;
        const int steps = static_cast<int>(std::ceil(std::log(1e12) / (0.5 * std::log1p(omega * omega * dt * dt))));
        VectorXd lambda;
        for (int step = 0; step < steps; ++step) cl::lab08::xpbd_step(particles, constraints, settings, lambda);
        const double stretch = total_stretch(particles, rest_length);
        CAPTURE(dt, iterations, steps, stretch, particles.x.col(1).transpose());
        REQUIRE(cl::test::near_rel(stretch, mass * g / stiffness, 1e-9));
        REQUIRE(cl::test::near(particles.x.col(1).normalized(), down, 1e-12));
      }
    }
  }
}

TEST_CASE("a hanging chain of N beads settles at total stretch mgN(N+1)/(2k)", "[lab08][pts=2]") {
  // K = 10(2N+1)² sweeps converge the step: for this tridiagonal system
  // Gauss-Seidel shrinks the error by about 1 − (π/(2N+1))² per sweep when
  // α̃ = 0, and compliance only adds to the diagonal, so the error left is
  // below e^(−10π²) ≈ 5e-43 of the prediction's Δt² g: round-off only. The
  // converged step is the implicit step, exact on this straight chain.
  const Vector3d gravity(0.0, -9.81, 0.0);
  const double g = 9.81;
  const Vector3d down(0.0, -1.0, 0.0);
  const double rest_length = 0.1;

  SECTION("started at its equilibrium at rest, one converged step leaves it there") {
    for (const int beads : {1, 4, 12}) {
      for (const double dt : {1e-3, 1.0 / 60.0, 0.5}) {
        for (const double stiffness : {10.0, 1e4}) {
          const double mass = 0.1;
          cl::Particles particles = chain(beads, mass, rest_length, stiffness, g, down, true);
          const cl::Particles start = particles;
          const ConstraintSet constraints = springs_of(beads, rest_length, stiffness);
          XpbdSettings settings;
          settings.dt = dt;
          settings.gravity = gravity;
          settings.iterations = 10 * (2 * beads + 1) * (2 * beads + 1);
          VectorXd lambda;
          cl::lab08::xpbd_step(particles, constraints, settings, lambda);
          const double expected = mass * g * beads * (beads + 1) / (2.0 * stiffness);
          const double scale = 1e-12 * (start.x.cwiseAbs().maxCoeff() + beads * dt * dt * g);
          CAPTURE(beads, dt, stiffness, settings.iterations, expected, lambda.transpose());
          REQUIRE(cl::test::near(particles.x, start.x, scale));
          REQUIRE(cl::test::near(total_stretch(particles, rest_length), expected, beads * scale));
          REQUIRE(lambda.size() == beads);
          for (int s = 0; s < beads; ++s) {
            CAPTURE(s);
            REQUIRE(cl::test::near_rel(lambda[s] / (dt * dt), -(beads - s) * mass * g, 1e-6));
          }
        }
      }
    }
  }

  SECTION("released at its rest lengths, it settles there") {
    // Converged steps are backward Euler for this linear chain: each mode's
    // amplitude shrinks by 1/√(1 + ω²Δt²) per step, the slowest (ω_min) the
    // least. Run until that factor is 1e-12; the stretch then matches to 1e-6
    // (a margin for the conversion between the modal and the position norms).
    struct Case {
      int beads;
      double mass, stiffness, dt;
    };
    for (const Case& c : {Case{12, 0.1, 100.0, 0.25}, Case{5, 0.05, 1e4, 0.1}, Case{3, 0.2, 50.0, 1.0 / 60.0}}) {
      cl::Particles particles = chain(c.beads, c.mass, rest_length, c.stiffness, g, down, false);
      const ConstraintSet constraints = springs_of(c.beads, rest_length, c.stiffness);
      XpbdSettings settings;
      settings.dt = c.dt;
      settings.gravity = gravity;
      settings.iterations = 10 * (2 * c.beads + 1) * (2 * c.beads + 1);
      const double omega = slowest_frequency(c.beads, c.mass, c.stiffness);
      const int steps =
          static_cast<int>(std::ceil(std::log(1e12) / (0.5 * std::log1p(omega * omega * c.dt * c.dt))));
      VectorXd lambda;
      for (int step = 0; step < steps; ++step) cl::lab08::xpbd_step(particles, constraints, settings, lambda);
      const double expected = c.mass * g * c.beads * (c.beads + 1) / (2.0 * c.stiffness);
      CAPTURE(c.beads, c.mass, c.stiffness, c.dt, omega, steps, settings.iterations);
      REQUIRE(cl::test::near_rel(total_stretch(particles, rest_length), expected, 1e-6));
    }
  }
}
