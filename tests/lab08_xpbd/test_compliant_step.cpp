// Graded test for lab08.2, xpbd_step against lab 07's compliant step: with
// enough sweeps XPBD solves the same implicit step, with the constraint kept
// nonlinear where lab 07 linearises it at the start of the step.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "tests/support/catch.h"

#include "pbd.h"
#include "step.h"
#include "tests/support/checks.h"
#include "xpbd.h"

using Eigen::Matrix3Xd;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

struct Chain {
  cl::Particles particles;
  std::vector<cl::Spring> springs;  // spring s joins particles s and s+1
};

// A chain of `beads` particles below a pin at the origin. `bent`: links of
// 0.1 m in random directions, rest lengths 0.99 … 1.01 times the start
// length, stiffness 10^U(2, 4) N/m, masses 10^U(−1.3, −0.7) kg, velocities in
// [−1, 1]³ m/s. Otherwise: hanging straight down at its rest lengths, at rest,
// equal masses of 0.1 kg and k = 1000 N/m.
Chain make_chain(std::mt19937_64& rng, int beads, bool bent) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Chain chain;
  cl::Particles& p = chain.particles;
  p.x.setZero(3, beads + 1);
  p.v.setZero(3, beads + 1);
  p.inv_mass.resize(beads + 1);
  p.inv_mass[0] = 0.0;
  for (int b = 1; b <= beads; ++b) {
    const Vector3d direction = bent ? Vector3d(unit(rng), unit(rng), unit(rng)).normalized() : Vector3d(0, -1, 0);
    p.x.col(b) = p.x.col(b - 1) + 0.1 * direction;
    p.inv_mass[b] = bent ? std::pow(10.0, 1.0 + 0.3 * unit(rng)) : 10.0;
    if (bent) p.v.col(b) = Vector3d(unit(rng), unit(rng), unit(rng));
    const double rest = bent ? 0.1 * (1.0 + 0.01 * unit(rng)) : 0.1;
    const double stiffness = bent ? std::pow(10.0, 3.0 + unit(rng)) : 1000.0;
    chain.springs.push_back({b - 1, b, rest, stiffness});
  }
  return chain;
}

struct Steps {
  cl::Particles xpbd, lab07;
  VectorXd xpbd_force;  // λ/Δt², N
  VectorXd lab07_force;  // λ, N
};

// One step of each from the same state. K = 10(2N+1)² sweeps converge XPBD
// (test_hanging.cpp: Gauss-Seidel on a chain contracts by about
// 1 − (π/(2N+1))² per sweep in the worst, straight and hard, case).
Steps step_both(const Chain& chain, double dt) {
  const Vector3d gravity(0.0, -9.81, 0.0);
  const int beads = static_cast<int>(chain.springs.size());
  Steps steps{chain.particles, chain.particles, {}, {}};
  cl::lab08::XpbdSettings xpbd;
  xpbd.dt = dt;
  xpbd.gravity = gravity;
  xpbd.iterations = 10 * (2 * beads + 1) * (2 * beads + 1);
  VectorXd lambda;
  cl::lab08::xpbd_step(steps.xpbd, cl::lab04::make_constraint_set(beads + 1, chain.springs), xpbd, lambda);
  steps.xpbd_force = lambda / (dt * dt);

  cl::lab07::StepSettings compliant;
  compliant.dt = dt;
  compliant.gravity = gravity;
  compliant.method = cl::lab07::Method::kSchur;
  const cl::lab07::StepResult result = cl::lab07::constrained_step(steps.lab07, chain.springs, compliant);
  REQUIRE(cl::test::solved(result));
  steps.lab07_force = result.lambda;
  return steps;
}

// The bound on how far apart the two steps may end. Lab 07 solves
//     φ(x) + J(x)(x⁺ − x) + α̃μ = 0,   x⁺ = p + W Jᵀ μ        (μ = λΔt²)
// and XPBD the same with φ(x⁺) itself, which exceeds the linearisation by the
// remainder r_s = φ_s(x⁺) − φ_s(x) − J_s(x)(x⁺ − x) ≈ ½|Δ⊥|²/ℓ, Δ⊥ the
// relative move of the spring's ends across it: O(Δt² v²/ℓ). The difference
// δx of the two results minimises ½‖δx‖²_M + ½ Σ (J_s δx + r_s)²/α̃_s, so it
// is no larger in the M-norm than translating the part of the chain below
// each spring s by r_s: |δx_p| <= √(Σm / m_min) Σ_s |r_s|. XPBD's moves also
// follow the gradient as it turns during the step, a term of order
// Δt³ |f| v/ℓ that falls faster than the first; the factor 2 covers it, and
// the translation argument is itself a worst case (the measured differences
// stay more than ten times below the bound on these chains).
double bound(const Chain& chain, const cl::Particles& after) {
  const Matrix3Xd& x = chain.particles.x;
  const Matrix3Xd& y = after.x;
  double remainder = 0.0;
  for (const cl::Spring& s : chain.springs) {
    const Vector3d d = x.col(s.i) - x.col(s.j);
    const Vector3d d_after = y.col(s.i) - y.col(s.j);
    const Vector3d n = d.normalized();
    remainder += std::abs((d_after.norm() - s.rest_length) - (d.norm() - s.rest_length) - n.dot(d_after - d));
  }
  double total_mass = 0.0, least_mass = std::numeric_limits<double>::infinity();
  for (Eigen::Index p = 0; p < chain.particles.size(); ++p) {
    const double w = chain.particles.inv_mass[p];
    if (w > 0.0) {
      total_mass += 1.0 / w;
      least_mass = std::min(least_mass, 1.0 / w);
    }
  }
  return 2.0 * std::sqrt(total_mass / least_mass) * remainder;
}

}  // namespace

TEST_CASE("with many iterations the XPBD step matches lab 07's compliant step", "[lab08][pts=2]") {
  SECTION("a chain hanging straight at rest: the constraint is linear along the motion, the steps agree") {
    // Every move is along the links, so φ(x⁺) = φ(x) + J(x⁺ − x) exactly and
    // the two steps solve the same system: round-off and iteration error only.
    std::mt19937_64 rng(97);
    for (const int beads : {1, 6}) {
      for (const double dt : {1e-3, 1.0 / 60.0, 0.2}) {
        const Chain chain = make_chain(rng, beads, false);
        const Steps steps = step_both(chain, dt);
        CAPTURE(beads, dt, steps.xpbd_force.transpose(), steps.lab07_force.transpose());
        REQUIRE(cl::test::near(steps.xpbd.x, steps.lab07.x, 1e-12));
        REQUIRE(cl::test::near(steps.xpbd.v, steps.lab07.v, 1e-12 / dt));
        REQUIRE(cl::test::near(steps.xpbd_force, steps.lab07_force, 1e-7 * steps.lab07_force.cwiseAbs().maxCoeff()));
      }
    }
  }

  SECTION("a bent, moving chain: the steps differ by the linearisation, O(dt squared)") {
    std::mt19937_64 rng(101);
    for (int trial = 0; trial < 6; ++trial) {
      const Chain chain = make_chain(rng, 8, true);
      std::vector<double> differences;
      for (const double dt : {1.0 / 60.0, 1e-2, 5e-3}) {
        const Steps steps = step_both(chain, dt);
        const double difference = cl::test::difference(steps.xpbd.x, steps.lab07.x).largest;
        const double allowed = bound(chain, steps.lab07) + 1e-13;
        CAPTURE(trial, dt, difference, allowed, chain.particles.x, chain.particles.v,
                chain.particles.inv_mass.transpose());
        REQUIRE(cl::test::near(steps.xpbd.x, steps.lab07.x, allowed));
        REQUIRE(cl::test::near(steps.xpbd.v, steps.lab07.v, allowed / dt));
        differences.push_back(difference);
      }
      // Second order: halving Δt from 1e-2 to 5e-3 divides the difference by about 4.
      CAPTURE(trial, differences[1], differences[2]);
      REQUIRE(differences[1] / differences[2] >= 3.0);
    }
  }
}
