// The trade's residuals (bench/step_residual.h) against what they are defined
// to be: the implicit-Euler residual is Δt² ‖∇g‖_{M⁻¹} / sqrt(m_tot) of a
// finite-difference gradient of lab 06's g and vanishes at g's analytic
// minimiser; the hard one vanishes at the analytic hard step, and measures
// exactly the move no constraint force explains, also where the springs are
// redundant (J M⁻¹ Jᵀ singular).
#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "bench/step_residual.h"
#include "labs/lab06_projective_dynamics/projective_dynamics.h"
#include "tests/support/checks.h"

using Eigen::Matrix3Xd;
using Eigen::Vector3d;

namespace {

constexpr double kDt = 1.0 / 60.0;

// A chain of four beads, the first pinned, of unequal masses and stiffnesses.
cl::lab06::Problem chain() {
  Eigen::VectorXd inv_mass(4);
  inv_mass << 0.0, 1.0 / 0.5, 1.0 / 2.0, 1.0 / 0.25;
  const std::vector<cl::Spring> springs{{0, 1, 0.3, 400.0}, {1, 2, 0.25, 900.0}, {2, 3, 0.4, 250.0}};
  return cl::lab06::make_problem(inv_mass, springs, kDt);
}

}  // namespace

TEST_CASE("step_residual is dt^2 times the M^-1 norm of a finite-difference gradient of g over sqrt(m_tot)") {
  const cl::lab06::Problem problem = chain();
  Matrix3Xd x(3, 4), y(3, 4);
  x << 0.0, 0.31, 0.52, 0.95,  //
      0.0, -0.02, -0.11, -0.07,  //
      0.0, 0.03, 0.01, -0.05;
  y = x;
  y.rightCols(3) += (Matrix3Xd(3, 3) << 0.01, -0.02, 0.015, -0.03, 0.01, -0.02, 0.005, 0.02, -0.01).finished();

  double weighted = 0.0, mass = 0.0;
  const double h = 1e-6;
  for (int p = 1; p < 4; ++p) {
    Vector3d gradient;
    for (int c = 0; c < 3; ++c) {
      Matrix3Xd plus = x, minus = x;
      plus(c, p) += h;
      minus(c, p) -= h;
      gradient[c] = (cl::lab06::objective(problem, plus, y) - cl::lab06::objective(problem, minus, y)) / (2.0 * h);
    }
    weighted += problem.inv_mass[p] * gradient.squaredNorm();
    mass += 1.0 / problem.inv_mass[p];
  }
  const double expected = kDt * kDt * std::sqrt(weighted / mass);
  CAPTURE(expected);
  REQUIRE(expected > 1e-6);  // the test point is far from stationary
  REQUIRE(cl::test::near_rel(cl::bench::step_residual(problem, x, y), expected, 1e-6, "residual (m)"));
}

TEST_CASE("step_residual vanishes at the analytic minimiser of g and is positive elsewhere") {
  // One bead of mass m on a spring (k, L) to a pin at the origin, y on the
  // x axis: m (z − Y)/Δt² + k (z − L) = 0 gives z = (m Y/Δt² + k L)/(m/Δt² + k).
  const double m = 0.2, k = 5e3, rest = 0.5, target = 0.8;
  Eigen::VectorXd inv_mass(2);
  inv_mass << 0.0, 1.0 / m;
  const cl::lab06::Problem problem = cl::lab06::make_problem(inv_mass, {{0, 1, rest, k}}, kDt);
  Matrix3Xd y = Matrix3Xd::Zero(3, 2);
  y(0, 1) = target;
  const double inertia = m / (kDt * kDt);
  Matrix3Xd minimiser = y;
  minimiser(0, 1) = (inertia * target + k * rest) / (inertia + k);
  const double at_y = cl::bench::step_residual(problem, y, y);
  CAPTURE(at_y, minimiser(0, 1));
  // At y only the spring pulls: Δt² k (Y − L)/m.
  REQUIRE(cl::test::near_rel(at_y, kDt * kDt * k * (target - rest) / m, 1e-12, "residual at y (m)"));
  REQUIRE(cl::test::at_most("residual at the minimiser / at y", cl::bench::step_residual(problem, minimiser, y) / at_y,
                            1e-12));
}

TEST_CASE("hard_residual: zero at the analytic hard step of a pendulum, and each part alone where only it is off") {
  // The hard step of one bead on a rod of length 1 to a pin at the origin is
  // y's projection onto the unit sphere.
  Eigen::VectorXd inv_mass(2);
  inv_mass << 0.0, 1.0 / 0.3;
  const cl::lab06::Problem problem = cl::lab06::make_problem(inv_mass, {{0, 1, 1.0, 1e6}}, kDt);
  Matrix3Xd y = Matrix3Xd::Zero(3, 2);
  y.col(1) << 0.6, -0.9, 0.2;
  Matrix3Xd step = y;
  step.col(1) = y.col(1).normalized();
  const double move = (step.col(1) - y.col(1)).norm();

  const cl::bench::HardResidual at_step = cl::bench::hard_residual(problem, step, y);
  CHECK(cl::test::at_most("violation at the hard step (m)", at_step.violation, 1e-15));
  CHECK(cl::test::at_most("stationarity at the hard step / move", at_step.stationarity / move, 1e-9));

  const cl::bench::HardResidual at_y = cl::bench::hard_residual(problem, y, y);
  CHECK(cl::test::near_rel(at_y.violation, y.col(1).norm() - 1.0, 1e-14, "violation at y (m)"));
  CHECK(cl::test::near(at_y.stationarity, 0.0, 1e-15, "stationarity at y (m)"));

  // On the sphere, rotated away from the step: the rod explains only d's
  // radial part; the rest, d − (d·n) n, is the stationarity residual.
  Matrix3Xd turned = step;
  turned.col(1) = Eigen::AngleAxisd(0.1, Vector3d(0.2, 0.5, 1.0).normalized()) * step.col(1);
  const Vector3d d = turned.col(1) - y.col(1);
  const Vector3d n = turned.col(1).normalized();
  const cl::bench::HardResidual at_turned = cl::bench::hard_residual(problem, turned, y);
  CHECK(cl::test::at_most("violation on the sphere (m)", at_turned.violation, 1e-15));
  CHECK(cl::test::near_rel(at_turned.stationarity, (d - d.dot(n) * n).norm(), 1e-9, "stationarity (m)"));
}

TEST_CASE("hard_residual: a redundant square (J M^-1 J^T singular) leaves exactly the out-of-plane move") {
  // A unit square in z = 0 with its two diagonals: six springs on four free
  // particles, whose in-plane motions (5 after the rigid ones) are all that J
  // sees, so J M⁻¹ Jᵀ (6 × 6) has rank 5. Any d = M⁻¹Jᵀμ is explained by the
  // constraint forces; an out-of-plane move t of one corner is M-orthogonal to
  // all of them and is the whole residual: sqrt(m_c |t|² / m_tot).
  Eigen::VectorXd inv_mass(4);
  inv_mass << 1.0, 0.5, 1.0 / 3.0, 0.25;
  const double diagonal = std::sqrt(2.0);
  const std::vector<cl::Spring> springs{{0, 1, 1.0, 1e6}, {1, 2, 1.0, 1e6},      {2, 3, 1.0, 1e6},
                                        {3, 0, 1.0, 1e6}, {0, 2, diagonal, 1e6}, {1, 3, diagonal, 1e6}};
  const cl::lab06::Problem problem = cl::lab06::make_problem(inv_mass, springs, kDt);
  Matrix3Xd x(3, 4);
  x << 0.0, 1.0, 1.0, 0.0,  //
      0.0, 0.0, 1.0, 1.0,   //
      0.0, 0.0, 0.0, 0.0;
  const double mu[6] = {0.3, -0.2, 0.5, 0.1, -0.4, 0.25};
  Matrix3Xd explained = Matrix3Xd::Zero(3, 4);  // M⁻¹Jᵀμ
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const Vector3d n = (x.col(springs[e].i) - x.col(springs[e].j)).normalized();
    explained.col(springs[e].i) += inv_mass[springs[e].i] * mu[e] * n;
    explained.col(springs[e].j) -= inv_mass[springs[e].j] * mu[e] * n;
  }
  const Vector3d t(0.0, 0.0, 0.02);
  Matrix3Xd y = x - explained;
  y.col(2) -= t;

  const cl::bench::HardResidual residual = cl::bench::hard_residual(problem, x, y);
  const double mass = 1.0 + 2.0 + 3.0 + 4.0;
  CHECK(cl::test::at_most("violation (m)", residual.violation, 1e-15));
  CHECK(cl::test::near_rel(residual.stationarity, std::sqrt(3.0 * t.squaredNorm() / mass), 1e-8, "stationarity (m)"));
  // Without t the move is all explained (the singular direction of J M⁻¹ Jᵀ
  // gets no part of J d, which lies in range(J)).
  const Matrix3Xd y_explained = x - explained;
  CHECK(cl::test::at_most("stationarity without t / |M⁻¹Jᵀμ|",
                          cl::bench::hard_residual(problem, x, y_explained).stationarity / explained.norm(), 1e-9));
}
