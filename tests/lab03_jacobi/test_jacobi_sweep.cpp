// Graded tests for lab03.1, jacobi_sweep. Analytic cases first, then
// invariants: order independence, thread independence, pins, momentum.

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>

#include "tests/support/catch.h"

#include "common/metrics.h"
#include "common/openmp.h"
#include "common/scene.h"
#include "gauss_seidel.h"
#include "jacobi.h"
#include "tests/support/checks.h"

using cl::Spring;
using cl::lab03::Averaging;
using cl::lab03::build_incidence;
using cl::lab03::jacobi_sweep;
using Eigen::Matrix3Xd;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

// Anchors at 0 and 2 on the x axis, rest lengths 1 and 1, the free particle
// at 1 + δ: both springs push it back by δ, so the sum is −2δ and the average −δ.
struct Anchored {
  Matrix3Xd x{3, 3};
  VectorXd inv_mass{{0.0, 1.0, 0.0}};
  std::vector<Spring> springs{Spring{0, 1, 1.0}, Spring{1, 2, 1.0}};
  explicit Anchored(double delta) {
    x << 0.0, 1.0 + delta, 2.0,  //
        0.0, 0.0, 0.0,           //
        0.0, 0.0, 0.0;
  }
  double displacement() const { return x(0, 1) - 1.0; }  // exact: x(0, 1) is near 1
};

// K sweeps, x ← x_next each time.
void sweeps(int count, Matrix3Xd& x, const VectorXd& inv_mass, const std::vector<Spring>& springs, double omega,
            Averaging averaging) {
  const cl::lab03::Incidence incidence = build_incidence(x.cols(), springs);
  Matrix3Xd x_next;
  for (int sweep = 0; sweep < count; ++sweep) {
    jacobi_sweep(x, x_next, inv_mass, springs, incidence, omega, averaging);
    x.swap(x_next);
  }
}

cl::Scene jittered_cloth(int n, const std::string& pins, int seed) {
  return cl::parse_scene(R"({"cloth": {"nx": )" + std::to_string(n) + R"(, "pin": )" + pins +
                             R"(, "springs": ["structural", "shear", "bending"]},
                             "jitter": {"amplitude": 0.02, "seed": )" + std::to_string(seed) + "}}",
                         "cloth.json");
}

}  // namespace

TEST_CASE("summed Jacobi without averaging overshoots to minus delta and never converges", "[lab03][pts=1]") {
  for (const double delta : {0.2, -0.1, 1e-4}) {
    CAPTURE(delta);
    Anchored scene(delta);
    const double start = scene.displacement();
    sweeps(1, scene.x, scene.inv_mass, scene.springs, 1.0, Averaging::kNone);
    REQUIRE(cl::test::near(scene.displacement(), -start, 1e-15, "displacement after one sweep"));
    sweeps(1, scene.x, scene.inv_mass, scene.springs, 1.0, Averaging::kNone);
    REQUIRE(cl::test::near(scene.displacement(), start, 1e-15, "displacement after two sweeps"));
    // It keeps bouncing between +δ and −δ: no progress, ever.
    sweeps(101, scene.x, scene.inv_mass, scene.springs, 1.0, Averaging::kNone);
    REQUIRE(cl::test::near(std::abs(scene.displacement()), std::abs(start), 1e-13, "|displacement| after 103 sweeps"));
  }
}

TEST_CASE("averaged Jacobi with relaxation omega leaves (1 - omega) delta", "[lab03][pts=2]") {
  for (const double omega : {0.0, 0.3, 0.5, 1.0, 1.5, 2.0, 2.5}) {
    for (const double delta : {0.2, -0.1, 1e-4}) {
      CAPTURE(omega, delta);
      Anchored scene(delta);
      const Matrix3Xd start = scene.x;
      const double before = scene.displacement();
      sweeps(1, scene.x, scene.inv_mass, scene.springs, omega, Averaging::kByCount);
      REQUIRE(cl::test::near(scene.displacement(), (1.0 - omega) * before, 1e-15, "displacement after one sweep"));
      // Everything else exactly as it was: the anchors, and y = z = 0 of the free particle.
      Matrix3Xd unchanged = start;
      unchanged(0, 1) = scene.x(0, 1);  // the free particle's x, checked just above
      REQUIRE(cl::test::near(scene.x, unchanged, 0.0, "particle"));
      if (omega == 0.0) REQUIRE(cl::test::near(scene.x, start, 0.0, "particle"));
    }
  }
}

TEST_CASE("any permutation of the springs gives the same sweep to round-off", "[lab03][pts=1]") {
  const cl::Scene scene = jittered_cloth(9, R"(["top-left"])", 3);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> log_mass(-1.0, 1.0);
  VectorXd inv_mass = scene.particles.inv_mass;
  for (Eigen::Index p = 0; p < inv_mass.size(); ++p) {
    if (inv_mass[p] > 0.0) inv_mass[p] = std::pow(10.0, log_mass(rng));
  }
  for (const auto& [omega, averaging] : {std::pair{1.0, Averaging::kByCount}, std::pair{1.7, Averaging::kByCount},
                                         std::pair{0.4, Averaging::kNone}}) {
    Matrix3Xd reference = scene.particles.x;
    sweeps(3, reference, inv_mass, scene.springs, omega, averaging);
    for (unsigned seed = 0; seed < 5; ++seed) {
      std::vector<Spring> permuted = scene.springs;
      std::mt19937 shuffle_rng(seed);
      std::shuffle(permuted.begin(), permuted.end(), shuffle_rng);
      // Swapping the two ends of a spring is the same constraint, too.
      for (std::size_t s = 0; s < permuted.size(); s += 2) std::swap(permuted[s].i, permuted[s].j);
      CAPTURE(omega, averaging == Averaging::kByCount, seed);
      Matrix3Xd x = scene.particles.x;
      sweeps(3, x, inv_mass, permuted, omega, averaging);
      REQUIRE(cl::test::near(x, reference, 1e-14, "particle"));
    }
  }
}

TEST_CASE("one and two threads give identical bits", "[lab03][pts=2]") {
  const cl::Scene scene = jittered_cloth(48, R"(["top-left", "top-right"])", 8);
  const int saved = cl::openmp_max_threads();
  for (const auto& [omega, averaging] : {std::pair{1.0, Averaging::kByCount}, std::pair{1.3, Averaging::kNone}}) {
    CAPTURE(omega, averaging == Averaging::kByCount);
    cl::set_openmp_threads(1);
    Matrix3Xd serial = scene.particles.x;
    sweeps(4, serial, scene.particles.inv_mass, scene.springs, omega, averaging);
    for (const int threads : {2, 3, 4}) {
      CAPTURE(threads);
      cl::set_openmp_threads(threads);
      Matrix3Xd parallel = scene.particles.x;
      sweeps(4, parallel, scene.particles.inv_mass, scene.springs, omega, averaging);
      REQUIRE(cl::test::at_least("the largest move of a particle over 4 sweeps", (parallel - scene.particles.x).colwise().norm().maxCoeff(), 1e-9));
      REQUIRE(cl::test::near(parallel, serial, 0.0, "particle"));
    }
  }
  cl::set_openmp_threads(saved);
}

TEST_CASE("pinned particles never move", "[lab03][pts=1]") {
  const cl::Scene scene = jittered_cloth(8, R"(["top-left", "top-right", "bottom-right"])", 4);
  for (const double omega : {0.5, 1.0, 1.9}) {
    for (const Averaging averaging : {Averaging::kByCount, Averaging::kNone}) {
      CAPTURE(omega, averaging == Averaging::kByCount);
      Matrix3Xd x = scene.particles.x;
      sweeps(20, x, scene.particles.inv_mass, scene.springs, omega, averaging);
      REQUIRE(cl::test::at_least("the largest move of a particle over 20 sweeps", (x - scene.particles.x).colwise().norm().maxCoeff(), 1e-9));
      for (Eigen::Index p = 0; p < x.cols(); ++p) {
        if (scene.particles.inv_mass[p] == 0.0) {
          REQUIRE(cl::test::near(x.col(p), scene.particles.x.col(p), 0.0, "pinned particle " + std::to_string(p)));
        }
      }
    }
  }
}

TEST_CASE("a sweep without pins leaves the total momentum unchanged", "[lab03][pts=1]") {
  // Each spring's two corrections cancel in Σ m Δx. The plain sum keeps that
  // for any graph; the average divides by each particle's count, so it keeps
  // it when every particle has the same count (here: a ring, 4 springs each).
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 10;
    Matrix3Xd x(3, n);
    VectorXd inv_mass(n);
    for (int p = 0; p < n; ++p) {
      x.col(p) = Vector3d(unit(rng), unit(rng), unit(rng));
      inv_mass[p] = std::pow(10.0, unit(rng));
    }
    std::vector<Spring> ring;
    for (int p = 0; p < n; ++p) {
      ring.push_back(Spring{p, (p + 1) % n, 0.5 + 0.3 * std::abs(unit(rng))});
      ring.push_back(Spring{p, (p + 2) % n, 0.8 + 0.3 * std::abs(unit(rng))});
    }
    std::vector<Spring> random_graph;
    for (int s = 0; s < 25; ++s) {
      const int i = static_cast<int>(rng() % n);
      random_graph.push_back(Spring{i, (i + 1 + static_cast<int>(rng() % (n - 1))) % n, 0.6});
    }
    const double omega = 0.2 + 1.7 * std::abs(unit(rng));
    for (const auto& [springs, averaging] : {std::pair{&ring, Averaging::kByCount},
                                             std::pair{&ring, Averaging::kNone},
                                             std::pair{&random_graph, Averaging::kNone}}) {
      CAPTURE(trial, x, inv_mass.transpose(), omega, springs == &ring, averaging == Averaging::kByCount);
      Matrix3Xd moved = x;
      sweeps(1, moved, inv_mass, *springs, omega, averaging);
      Vector3d momentum = Vector3d::Zero();
      double scale = 0.0;
      for (int p = 0; p < n; ++p) {
        momentum += (moved.col(p) - x.col(p)) / inv_mass[p];
        scale += (moved.col(p) - x.col(p)).norm() / inv_mass[p];
      }
      REQUIRE(scale > 0.0);
      REQUIRE(cl::test::near(momentum.norm(), 0.0, 1e-13 * scale, "‖Σ m Δx‖"));
    }
  }
}

TEST_CASE("on the same chain Jacobi needs more sweeps than Gauss-Seidel for the same error", "[lab03][pts=1]") {
  constexpr double kTolerance = 1e-8;
  constexpr int kCap = 20'000;
  for (const int seed : {1, 2}) {
    const std::string text = R"({"chain": {"links": 20, "length": 0.1, "pin": "first"},
                                 "jitter": {"amplitude": 0.01, "seed": )" + std::to_string(seed) + "}}";
    const cl::Scene scene = cl::parse_scene(text, "chain.json");
    std::vector<int> order(scene.springs.size());
    std::iota(order.begin(), order.end(), 0);
    Matrix3Xd x = scene.particles.x;
    int gauss_seidel = kCap + 1;
    for (int sweep = 1; sweep <= kCap; ++sweep) {
      cl::lab02::gauss_seidel_sweep(x, scene.particles.inv_mass, scene.springs, order);
      if (cl::strain_stats(x, scene.springs).max <= kTolerance) {
        gauss_seidel = sweep;
        break;
      }
    }
    x = scene.particles.x;
    int jacobi = kCap + 1;
    for (int sweep = 1; sweep <= kCap; ++sweep) {
      sweeps(1, x, scene.particles.inv_mass, scene.springs, 1.0, Averaging::kByCount);
      if (cl::strain_stats(x, scene.springs).max <= kTolerance) {
        jacobi = sweep;
        break;
      }
    }
    CAPTURE(text, gauss_seidel, jacobi);
    REQUIRE(cl::test::at_most("Gauss-Seidel sweeps to a max strain error of 1e-8 (cap + 1: not reached)",
                              gauss_seidel, kCap));
    REQUIRE(cl::test::at_least("Jacobi sweeps to the same error (bound: Gauss-Seidel's + 1)", jacobi,
                               gauss_seidel + 1));
  }
}

TEST_CASE("x_next is resized and bad shapes or bad omega throw std::invalid_argument", "[lab03][pts=1]") {
  Anchored scene(0.1);
  const cl::lab03::Incidence incidence = build_incidence(3, scene.springs);
  SECTION("x_next is resized") {
    // Empty, too many columns, too few: a driver may hand in any buffer.
    for (const Eigen::Index columns : {0, 7, 1}) {
      CAPTURE(columns);
      Matrix3Xd x_next = Matrix3Xd::Constant(3, columns, 42.0);
      jacobi_sweep(scene.x, x_next, scene.inv_mass, scene.springs, incidence, 1.0, Averaging::kByCount);
      REQUIRE(cl::test::near(static_cast<double>(x_next.cols()), 3.0, 0.0, "columns of x_next"));
      Matrix3Xd expected = scene.x;
      expected(0, 1) = 1.0;  // the free particle, back at rest; the anchors unchanged
      REQUIRE(cl::test::near(x_next, expected, 1e-15, "particle"));
    }
  }
  SECTION("throws") {
    Matrix3Xd x_next;
    for (const double omega : {-0.5, std::nan(""), HUGE_VAL}) {
      CAPTURE(omega);
      REQUIRE_THROWS_AS(jacobi_sweep(scene.x, x_next, scene.inv_mass, scene.springs, incidence, omega,
                                     Averaging::kByCount),
                        std::invalid_argument);
    }
    REQUIRE_THROWS_AS(jacobi_sweep(scene.x, x_next, VectorXd::Ones(2), scene.springs, incidence, 1.0,
                                   Averaging::kByCount),
                      std::invalid_argument);
    const cl::lab03::Incidence other = build_incidence(3, {Spring{0, 1, 1.0}});
    REQUIRE_THROWS_AS(jacobi_sweep(scene.x, x_next, scene.inv_mass, scene.springs, other, 1.0, Averaging::kByCount),
                      std::invalid_argument);
    REQUIRE_THROWS_AS(jacobi_sweep(scene.x, x_next, VectorXd{{0.0, -1.0, 0.0}}, scene.springs, incidence, 1.0,
                                   Averaging::kByCount),
                      std::invalid_argument);
    // A bad rest length is refused before the parallel loop too: thrown inside
    // it, project_distance's exception would end the process instead.
    for (const double rest_length : {-0.5, std::nan(""), HUGE_VAL}) {
      CAPTURE(rest_length);
      std::vector<Spring> springs = scene.springs;
      springs[1].rest_length = rest_length;
      REQUIRE_THROWS_AS(jacobi_sweep(scene.x, x_next, scene.inv_mass, springs, incidence, 1.0, Averaging::kByCount),
                        std::invalid_argument);
    }
  }
}
