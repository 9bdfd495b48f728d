// Ungraded tests of lab 11's given code ([lab11_given], run on the reference
// by ctest -L unit): the accelerated loop that PD, Jacobi PBD and lab 12's VBD
// share, and the estimate of rho from plain iterations, on Jacobi for
// tridiag(-1, 2, -1) (linear_splitting.h).
#include <cmath>
#include <limits>
#include <vector>

#include "tests/support/catch.h"

#include "accelerated.h"
#include "linear_splitting.h"
#include "tests/support/checks.h"

namespace {

constexpr Eigen::Index kN = 8;

Eigen::Matrix3Xd right_hand_side() {
  Eigen::Matrix3Xd b(3, kN);
  for (Eigen::Index p = 0; p < kN; ++p) b.col(p) = Eigen::Vector3d(1.0, -0.5 * static_cast<double>(p), 0.25);
  return b;
}

// ‖b − x A‖²: Jacobi (r ← (I − A/2) r, ‖I − A/2‖ < 1) lowers it at every iteration.
double residual(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& b) {
  return (b - lab11_test::times_a(x)).squaredNorm();
}

struct Run {
  Eigen::Matrix3Xd x;
  cl::lab11::StepReport report;
  std::vector<cl::lab11::IterationRecord> records;
};

Run run(const cl::lab11::AcceleratedLoop& loop, const Eigen::VectorXd& inv_mass = Eigen::VectorXd::Ones(kN)) {
  const Eigen::Matrix3Xd b = right_hand_side();
  Run result;
  result.x = Eigen::Matrix3Xd::Zero(3, kN);
  const Eigen::Matrix3Xd held = result.x;
  result.report = cl::lab11::accelerated_iterations(
      result.x, held, inv_mass,
      [&](const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& plain) {
        plain = lab11_test::jacobi(x, b);
        for (Eigen::Index p = 0; p < kN; ++p) {
          if (!(inv_mass[p] > 0.0)) plain.col(p) = x.col(p);
        }
      },
      [&](const Eigen::Matrix3Xd& x) { return residual(x, b); }, loop,
      [&](const cl::lab11::IterationRecord& record, const Eigen::Matrix3Xd&) {
        result.records.push_back(record);
        return false;
      });
  return result;
}

cl::lab11::AcceleratedLoop loop_of(int iterations, bool accelerated, double rho) {
  cl::lab11::AcceleratedLoop loop;
  loop.iterations = iterations;
  loop.accelerated = accelerated;
  loop.rho = rho;
  loop.name = "jacobi";
  loop.unit = "sweep";
  return loop;
}

}  // namespace

TEST_CASE("the accelerated loop: plain and rho = 0 are the plain iteration bit for bit", "[lab11_given]") {
  const Eigen::Matrix3Xd b = right_hand_side();
  Eigen::Matrix3Xd expected = Eigen::Matrix3Xd::Zero(3, kN);
  for (int k = 0; k < 30; ++k) expected = lab11_test::jacobi(expected, b);
  const Run plain = run(loop_of(30, false, 0.0));
  const Run zero = run(loop_of(30, true, 0.0));
  REQUIRE(plain.x == expected);
  REQUIRE(zero.x == expected);
  REQUIRE(zero.report.restarts == 0);
  REQUIRE(plain.report.iterations_done == 30);
  REQUIRE(plain.records.size() == 31);  // iteration 0 and every iteration
  REQUIRE(plain.report.objective == residual(expected, b));
}

TEST_CASE("the accelerated loop: the first S weights are 1, then the Chebyshev weights; the merit never rises",
          "[lab11_given]") {
  const double rho = lab11_test::splitting_rho(kN);
  cl::lab11::AcceleratedLoop loop = loop_of(60, true, rho);
  loop.delay = 4;
  const Run accelerated = run(loop);
  CAPTURE(rho);
  REQUIRE(accelerated.records.size() == 61);
  for (int k = 1; k <= 4; ++k) REQUIRE(accelerated.records[static_cast<std::size_t>(k)].omega == 1.0);
  REQUIRE_FALSE(accelerated.records[5].restarted);
  REQUIRE(cl::test::near(accelerated.records[5].omega, 2.0 / (2.0 - rho * rho), 1e-15));
  for (std::size_t k = 1; k < accelerated.records.size(); ++k) {
    CAPTURE(k);
    const double before = accelerated.records[k - 1].objective;
    REQUIRE(accelerated.records[k].objective <= before + cl::lab11::kRestartSlack * std::abs(before));
  }
  // Closer to the fixed point than the plain iteration after as many iterations.
  REQUIRE(accelerated.report.objective < 1e-6 * run(loop_of(60, false, 0.0)).report.objective);
}

TEST_CASE("the accelerated loop holds pinned columns and stops at the tolerance", "[lab11_given]") {
  Eigen::VectorXd inv_mass = Eigen::VectorXd::Ones(kN);
  inv_mass[3] = 0.0;
  cl::lab11::AcceleratedLoop loop = loop_of(500, true, 0.9);
  loop.gamma = 0.9;
  loop.tolerance = 1e-10;
  const Run held = run(loop, inv_mass);
  REQUIRE(held.x.col(3) == Eigen::Vector3d::Zero());
  REQUIRE(held.report.converged);
  REQUIRE(held.report.iterations_done < 500);
  REQUIRE(held.report.iterations_done == static_cast<int>(held.records.size()) - 1);
}

TEST_CASE("the accelerated loop stops at a non-finite iterate and names the iteration", "[lab11_given]") {
  Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, 2);
  int calls = 0;
  const cl::lab11::StepReport report = cl::lab11::accelerated_iterations(
      x, Eigen::Matrix3Xd::Zero(3, 2), Eigen::VectorXd::Ones(2),
      [&](const Eigen::Matrix3Xd& q, Eigen::Matrix3Xd& plain) {
        plain = q.array() + 1.0;
        if (++calls == 3) plain(1, 1) = std::numeric_limits<double>::quiet_NaN();
      },
      [](const Eigen::Matrix3Xd& q) { return q.squaredNorm(); }, loop_of(10, false, 0.0));
  REQUIRE(report.iterations_done == 3);
  REQUIRE(report.problem == "jacobi: non-finite positions after sweep 3");
}

TEST_CASE("estimate_plain_rho measures the spectral radius of a plain iteration", "[lab11_given]") {
  const Eigen::Matrix3Xd b = right_hand_side();
  const cl::lab11::PlainIteration jacobi = [&](const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& plain) {
    plain = lab11_test::jacobi(x, b);
  };
  const double rho = cl::lab11::estimate_plain_rho(Eigen::Matrix3Xd::Zero(3, kN), jacobi, 200, 1.0);
  REQUIRE(cl::test::near(rho, lab11_test::splitting_rho(kN), 1e-6));
  // At the fixed point the first update is round-off: nothing to measure.
  Eigen::Matrix3Xd solution = Eigen::Matrix3Xd::Zero(3, kN);
  for (int k = 0; k < 2000; ++k) solution = lab11_test::jacobi(solution, b);
  REQUIRE(cl::lab11::estimate_plain_rho(solution, jacobi, 200, 1e6) == 0.0);
  REQUIRE_THROWS_AS(cl::lab11::estimate_plain_rho(solution, jacobi, 1, 1.0), std::invalid_argument);
}
