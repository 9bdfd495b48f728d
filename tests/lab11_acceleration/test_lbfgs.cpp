// Graded tests of lab11.5: the L-BFGS two-loop recursion.
#include <random>
#include <stdexcept>
#include <vector>

#include "tests/support/catch.h"
#include <Eigen/Dense>

#include "acceleration.h"
#include "tests/support/checks.h"

using cl::lab11::CurvaturePair;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

// A random symmetric positive definite n × n matrix with eigenvalues in [1, 1 + spread].
MatrixXd random_spd(std::mt19937_64& rng, Eigen::Index n, double spread) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  MatrixXd m(n, n);
  for (Eigen::Index r = 0; r < n; ++r) {
    for (Eigen::Index c = 0; c < n; ++c) m(r, c) = unit(rng);
  }
  const Eigen::HouseholderQR<MatrixXd> qr(m);
  const MatrixXd q = qr.householderQ();
  VectorXd eigenvalues(n);
  for (Eigen::Index i = 0; i < n; ++i) eigenvalues[i] = 1.0 + spread * (0.5 + 0.5 * unit(rng));
  return q * eigenvalues.asDiagonal() * q.transpose();
}

VectorXd random_vector(std::mt19937_64& rng, Eigen::Index n) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v[i] = unit(rng);
  return v;
}

}  // namespace

TEST_CASE("the two-loop recursion equals the dense BFGS inverse update of the same pairs to 1e-10",
          "[lab11][pts=1]") {
  // Every mistake fails here; the three cases below each isolate one of them.
  // H_(i+1) = (I − ρ_i s_i y_iᵀ) H_i (I − ρ_i y_i s_iᵀ) + ρ_i s_i s_iᵀ, ρ_i = 1/(s_iᵀ y_i),
  // from H_0 = A⁻¹, over the pairs with s_iᵀ y_i > 0, oldest first.
  std::mt19937_64 rng(1105);
  for (int trial = 0; trial < 6; ++trial) {
    const Eigen::Index n = 4 + 3 * trial;
    const MatrixXd a = random_spd(rng, n, 10.0);
    const MatrixXd hessian = random_spd(rng, n, 100.0);  // the "true" curvature the pairs sample
    const Eigen::LLT<MatrixXd> a_factor(a);
    const cl::lab11::InverseApply initial = [&](const VectorXd& v) { return VectorXd(a_factor.solve(v)); };
    std::vector<CurvaturePair> pairs;
    const int count = trial;  // 0 … 5 pairs
    for (int i = 0; i < count; ++i) {
      const VectorXd s = random_vector(rng, n);
      pairs.push_back({s, hessian * s});
    }
    if (trial >= 2) {  // one pair of negative curvature, in the middle: skipped
      const VectorXd s = random_vector(rng, n);
      pairs.insert(pairs.begin() + 1, {s, -hessian * s});
    }
    MatrixXd h = a_factor.solve(MatrixXd::Identity(n, n));
    for (const CurvaturePair& pair : pairs) {
      const double curvature = pair.s.dot(pair.y);
      if (!(curvature > 0.0)) continue;
      const MatrixXd v = MatrixXd::Identity(n, n) - pair.y * pair.s.transpose() / curvature;
      h = v.transpose() * h * v + pair.s * pair.s.transpose() / curvature;
    }
    const VectorXd gradient = random_vector(rng, n);
    const VectorXd expected = -h * gradient;
    const VectorXd direction = cl::lab11::lbfgs_direction(gradient, pairs, initial);
    CAPTURE(trial, n, pairs.size());
    REQUIRE(cl::test::near(direction, expected, 1e-10 * expected.cwiseAbs().maxCoeff()));
    REQUIRE(gradient.dot(direction) < 0.0);  // a descent direction
  }
}

TEST_CASE("the initial inverse enters unscaled: without pairs d = -A^-1 g and with one pair its closed form",
          "[lab11][pts=1]") {
  // A scaled H₀ (Nocedal and Wright's γ = sᵀy/yᵀy, or the identity) fails
  // here; the loops' order and the skip cannot matter with one good pair.
  std::mt19937_64 rng(1106);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::Index n = 5 + 2 * trial;
    const MatrixXd a = random_spd(rng, n, 5.0);
    const Eigen::LLT<MatrixXd> a_factor(a);
    const cl::lab11::InverseApply initial = [&](const VectorXd& v) { return VectorXd(a_factor.solve(v)); };
    const VectorXd gradient = random_vector(rng, n);
    const VectorXd pd_direction = -a_factor.solve(gradient);
    CAPTURE(trial, n);
    // No pairs: d = −A⁻¹∇g, projective dynamics' step (README.md).
    REQUIRE(cl::test::near(cl::lab11::lbfgs_direction(gradient, {}, initial), pd_direction,
                           1e-14 * pd_direction.cwiseAbs().maxCoeff(), "direction"));
    // One pair (s, y) and a gradient with sᵀ∇g = 0: the first loop leaves ∇g
    // alone (α = 0), so d = −(A⁻¹∇g − ρ s yᵀA⁻¹∇g), ρ = 1/(sᵀy), with A⁻¹ as given.
    const VectorXd s = random_vector(rng, n);
    const VectorXd y = a * s + random_spd(rng, n, 3.0) * s;
    const VectorXd g = gradient - s * (s.dot(gradient) / s.squaredNorm());
    const VectorXd h0g = a_factor.solve(g);
    const VectorXd expected = -(h0g - s * (y.dot(h0g) / s.dot(y)));
    REQUIRE(cl::test::near(cl::lab11::lbfgs_direction(g, {{s, y}}, initial), expected,
                           1e-12 * expected.cwiseAbs().maxCoeff(), "direction"));
  }
}

TEST_CASE("a pair with non-positive curvature is skipped in both loops", "[lab11][pts=1]") {
  // Skipping a pair leaves the direction of the other pairs: the same with or
  // without it. A pair with sᵀy <= 0 used anyway changes d (sᵀy < 0) or
  // divides by zero (sᵀy = 0); skipped in one loop only, d changes too.
  std::mt19937_64 rng(1107);
  const Eigen::Index n = 9;
  const MatrixXd a = random_spd(rng, n, 5.0);
  const MatrixXd hessian = random_spd(rng, n, 50.0);
  const Eigen::LLT<MatrixXd> a_factor(a);
  const cl::lab11::InverseApply initial = [&](const VectorXd& v) { return VectorXd(a_factor.solve(v)); };
  const VectorXd gradient = random_vector(rng, n);
  const VectorXd pd_direction = -a_factor.solve(gradient);
  // Only bad pairs: all skipped, PD's direction.
  const VectorXd s = random_vector(rng, n);
  const std::vector<CurvaturePair> bad{{s, -s}, {s, VectorXd::Zero(n)}};  // sᵀy < 0, sᵀy = 0 exactly
  REQUIRE(cl::test::near(cl::lab11::lbfgs_direction(gradient, bad, initial), pd_direction,
                         1e-14 * pd_direction.cwiseAbs().maxCoeff(), "direction"));
  // A bad pair between good ones: the direction of the good ones alone.
  std::vector<CurvaturePair> good;
  for (int i = 0; i < 3; ++i) {
    const VectorXd si = random_vector(rng, n);
    good.push_back({si, hessian * si});
  }
  const VectorXd without = cl::lab11::lbfgs_direction(gradient, good, initial);
  for (const CurvaturePair& skipped : bad) {
    std::vector<CurvaturePair> with = good;
    with.insert(with.begin() + 1, skipped);
    CAPTURE(skipped.s.dot(skipped.y));
    REQUIRE(cl::test::near(cl::lab11::lbfgs_direction(gradient, with, initial), without,
                           1e-14 * without.cwiseAbs().maxCoeff(), "direction"));
  }
  // Refused: a pair of the wrong size.
  const std::vector<CurvaturePair> wrong{{VectorXd::Ones(n + 1), VectorXd::Ones(n + 1)}};
  REQUIRE_THROWS_AS(cl::lab11::lbfgs_direction(gradient, wrong, initial), std::invalid_argument);
  const std::vector<CurvaturePair> half{{VectorXd::Ones(n), VectorXd::Ones(n - 1)}};
  REQUIRE_THROWS_AS(cl::lab11::lbfgs_direction(gradient, half, initial), std::invalid_argument);
}

TEST_CASE("the newest pair's secant condition holds so the first loop runs newest first", "[lab11][pts=1]") {
  // BFGS ends with the newest pair's update, after which H y_newest = s_newest
  // whatever came before (H₀ and the older pairs): the direction for the
  // gradient y_newest is −s_newest. Loops in the wrong order apply the pairs
  // newest first, so the condition holds for the oldest pair instead.
  std::mt19937_64 rng(1108);
  for (int count = 2; count <= 5; ++count) {
    const Eigen::Index n = 8;
    const MatrixXd a = random_spd(rng, n, 5.0);
    const MatrixXd hessian = random_spd(rng, n, 50.0);
    const Eigen::LLT<MatrixXd> a_factor(a);
    const cl::lab11::InverseApply initial = [&](const VectorXd& v) { return VectorXd(a_factor.solve(v)); };
    std::vector<CurvaturePair> pairs;
    for (int i = 0; i < count; ++i) {
      const VectorXd s = random_vector(rng, n);
      pairs.push_back({s, hessian * s});
    }
    const CurvaturePair& newest = pairs.back();
    CAPTURE(count);
    REQUIRE(cl::test::near(cl::lab11::lbfgs_direction(newest.y, pairs, initial), VectorXd(-newest.s),
                           1e-11 * newest.s.cwiseAbs().maxCoeff(), "direction"));
  }
}
