// Graded tests for lab02.1, gauss_seidel_sweep. Properties and analytic cases.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>

#include "tests/support/catch.h"

#include "common/metrics.h"
#include "common/scene.h"
#include "gauss_seidel.h"
#include "tests/support/checks.h"

using cl::Spring;
using cl::lab02::gauss_seidel_sweep;
using Eigen::Matrix3Xd;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

std::vector<int> forward_order(std::size_t count) {
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), 0);
  return order;
}

std::vector<int> reverse_order(std::size_t count) {
  std::vector<int> order = forward_order(count);
  std::reverse(order.begin(), order.end());
  return order;
}

std::vector<int> shuffled_order(std::size_t count, unsigned seed) {
  std::vector<int> order = forward_order(count);
  std::mt19937 rng(seed);
  std::shuffle(order.begin(), order.end(), rng);
  return order;
}

// A chain pinned at its first particle, jittered after its rest lengths were set.
std::string chain_json(int links, double jitter, int seed) {
  return R"({"chain": {"links": )" + std::to_string(links) + R"(, "length": 0.1, "pin": "first"},
             "jitter": {"amplitude": )" + std::to_string(jitter) + R"(, "seed": )" + std::to_string(seed) + "}}";
}

// Sweeps in a fixed order until the max strain error is <= tolerance; returns
// the number of sweeps, or -1 if `cap` sweeps were not enough.
int sweeps_to(double tolerance, int cap, Matrix3Xd& x, const VectorXd& inv_mass, const std::vector<Spring>& springs,
              const std::vector<int>& order) {
  for (int sweep = 1; sweep <= cap; ++sweep) {
    gauss_seidel_sweep(x, inv_mass, springs, order);
    if (cl::strain_stats(x, springs).max <= tolerance) return sweep;
  }
  return -1;
}

}  // namespace

TEST_CASE("one constraint is satisfied after one sweep", "[lab02][pts=1]") {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    Matrix3Xd x(3, 2);
    x.col(0) = Vector3d(unit(rng), unit(rng), unit(rng));
    x.col(1) = Vector3d(unit(rng), unit(rng), unit(rng));
    const VectorXd inv_mass{{trial % 7 == 0 ? 0.0 : 1.5 + unit(rng), 1.0 + unit(rng) * 0.9}};
    const double rest_length = (0.2 + std::abs(unit(rng))) * (x.col(0) - x.col(1)).norm();
    const std::vector<Spring> springs{Spring{trial % 2, 1 - trial % 2, rest_length}};
    CAPTURE(x, inv_mass.transpose(), rest_length, springs[0].i);
    gauss_seidel_sweep(x, inv_mass, springs, {0});
    REQUIRE(cl::test::near((x.col(0) - x.col(1)).norm(), rest_length, 1e-12 * rest_length, "length after the sweep"));
  }
}

TEST_CASE("a particle between two pinned anchors reaches its fixed point in one sweep", "[lab02][pts=1]") {
  // Anchors at 0 and 2 on the x axis, rest lengths L and 2 − L: the only
  // feasible position of the free particle is (L, 0, 0). Started on the axis,
  // the first projection puts it there and the second finds nothing to do.
  for (const double rest_length : {1.0, 0.7, 1.6}) {
    for (const double delta : {0.3, -0.4, 0.05, 1e-6}) {
      for (const bool reverse : {false, true}) {
        CAPTURE(rest_length, delta, reverse);
        Matrix3Xd x(3, 3);
        x << 0.0, rest_length + delta, 2.0,  //
            0.0, 0.0, 0.0,                   //
            0.0, 0.0, 0.0;
        const VectorXd inv_mass{{0.0, 1.0, 0.0}};
        const std::vector<Spring> springs{Spring{0, 1, rest_length}, Spring{1, 2, 2.0 - rest_length}};
        const std::vector<int> order = reverse ? std::vector<int>{1, 0} : std::vector<int>{0, 1};
        gauss_seidel_sweep(x, inv_mass, springs, order);
        REQUIRE(cl::test::near((x.col(1) - Vector3d(rest_length, 0.0, 0.0)).norm(), 0.0, 1e-15, "‖x_1 − (L, 0, 0)‖"));
        const Vector3d after_one = x.col(1);
        gauss_seidel_sweep(x, inv_mass, springs, order);
        REQUIRE(cl::test::near((x.col(1) - after_one).norm(), 0.0, 1e-15, "‖x_1 moved by the second sweep‖"));
      }
    }
  }
}

TEST_CASE("the strain error of a feasible chain falls to 1e-10", "[lab02][pts=2]") {
  std::vector<std::pair<std::string, cl::Scene>> scenes;
  scenes.emplace_back("perturbed-chain.json", cl::load_scene(std::string(CL_LAB_SCENE_DIR) + "/perturbed-chain.json"));
  for (const int seed : {1, 2, 3}) {
    const std::string text = chain_json(10 * seed, 0.02, seed);
    scenes.emplace_back(text, cl::parse_scene(text, "generated.json"));
  }
  for (const auto& [source, scene] : scenes) {
    const std::size_t m = scene.springs.size();
    for (const std::vector<int>& order : {forward_order(m), reverse_order(m), shuffled_order(m, 5)}) {
      CAPTURE(source, order);
      Matrix3Xd x = scene.particles.x;
      REQUIRE(cl::strain_stats(x, scene.springs).max > 1e-3);
      const int sweeps = sweeps_to(1e-10, 5000, x, scene.particles.inv_mass, scene.springs, order);
      // sweeps > 0 exactly when the max strain error reached 1e-10 within the cap.
      CAPTURE(sweeps);
      REQUIRE(cl::test::at_most("max strain error after " + std::to_string(sweeps > 0 ? sweeps : 5000) + " sweeps",
                                cl::strain_stats(x, scene.springs).max, 1e-10));
      REQUIRE(x.allFinite());
    }
  }
}

TEST_CASE("forward and reverse orders reach different states that both satisfy the constraints", "[lab02][pts=2]") {
  for (const int seed : {7, 8, 9}) {
    const std::string text = chain_json(12, 0.03, seed);
    CAPTURE(text);
    const cl::Scene scene = cl::parse_scene(text, "generated.json");
    const std::size_t m = scene.springs.size();
    Matrix3Xd forward = scene.particles.x;
    Matrix3Xd reverse = scene.particles.x;
    const int forward_sweeps = sweeps_to(1e-12, 5000, forward, scene.particles.inv_mass, scene.springs, forward_order(m));
    const int reverse_sweeps = sweeps_to(1e-12, 5000, reverse, scene.particles.inv_mass, scene.springs, reverse_order(m));
    CAPTURE(forward_sweeps, reverse_sweeps);
    REQUIRE(forward_sweeps > 0);
    REQUIRE(reverse_sweeps > 0);
    // Far above round-off: the orders pick different points of the feasible set.
    double difference = 0.0;
    Eigen::Index where = 0;
    for (Eigen::Index p = 0; p < forward.cols(); ++p) {
      const double apart = (forward.col(p) - reverse.col(p)).norm();
      if (apart > difference) {
        difference = apart;
        where = p;
      }
    }
    REQUIRE(cl::test::at_least("largest ‖forward − reverse‖, at particle " + std::to_string(where), difference, 1e-6));
  }
}

TEST_CASE("pinned particles never move", "[lab02][pts=1]") {
  const cl::Scene cloth = cl::parse_scene(R"({"cloth": {"nx": 8, "ny": 8, "pin": ["top-left", "top-right",
      "bottom-left"], "springs": ["structural", "shear", "bending"]}, "jitter": {"amplitude": 0.05, "seed": 4}})",
                                          "cloth.json");
  const cl::Scene chain = cl::parse_scene(R"({"chain": {"links": 6, "pin": "both"},
      "jitter": {"amplitude": 0.2, "seed": 5}})", "chain.json");
  for (const cl::Scene* scene : {&cloth, &chain}) {
    const std::size_t m = scene->springs.size();
    for (const std::vector<int>& order : {forward_order(m), reverse_order(m), shuffled_order(m, 9)}) {
      CAPTURE(scene->source, order);
      Matrix3Xd x = scene->particles.x;
      // The chain's pins are stretched apart: the sweeps keep pulling on them.
      if (scene == &chain) x.col(6) += Vector3d(0.5, 0.0, 0.0);
      const Matrix3Xd start = x;
      for (int sweep = 0; sweep < 30; ++sweep) gauss_seidel_sweep(x, scene->particles.inv_mass, scene->springs, order);
      REQUIRE(cl::test::at_least("the largest move of a particle over 30 sweeps", (x - start).colwise().norm().maxCoeff(), 1e-9));
      for (Eigen::Index p = 0; p < x.cols(); ++p) {
        if (scene->particles.inv_mass[p] == 0.0) {
          REQUIRE(cl::test::near(x.col(p), start.col(p), 0.0, "pinned particle " + std::to_string(p)));
        }
      }
    }
  }
}

TEST_CASE("a sweep without pins leaves the total momentum unchanged", "[lab02][pts=1]") {
  // Σ m_i Δx_i = 0 over a whole sweep: every projection conserves it.
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 12;
    Matrix3Xd x = Matrix3Xd::Zero(3, n);
    VectorXd inv_mass(n);
    for (int p = 0; p < n; ++p) {
      x.col(p) = Vector3d(unit(rng), unit(rng), unit(rng));
      inv_mass[p] = std::pow(10.0, unit(rng));  // 0.1 … 10 per kg
    }
    std::vector<Spring> springs;
    for (int s = 0; s < 30; ++s) {
      const int i = static_cast<int>(rng() % n);
      const int j = (i + 1 + static_cast<int>(rng() % (n - 1))) % n;
      springs.push_back(Spring{i, j, 0.5 + 0.5 * std::abs(unit(rng))});
    }
    CAPTURE(trial, x, inv_mass.transpose());
    const Matrix3Xd start = x;
    gauss_seidel_sweep(x, inv_mass, springs, shuffled_order(springs.size(), static_cast<unsigned>(trial)));
    Vector3d momentum = Vector3d::Zero();
    double scale = 0.0;
    for (int p = 0; p < n; ++p) {
      momentum += (x.col(p) - start.col(p)) / inv_mass[p];
      scale += (x.col(p) - start.col(p)).norm() / inv_mass[p];
    }
    REQUIRE(scale > 0.0);
    REQUIRE(cl::test::near(momentum.norm(), 0.0, 1e-13 * scale, "‖Σ m Δx‖"));
  }
}

TEST_CASE("an empty order is a no-op and bad shapes or spring indices throw std::invalid_argument", "[lab02][pts=1]") {
  Matrix3Xd x(3, 3);
  x << 0, 1, 2, 0, 0, 0, 0, 0, 0;
  const VectorXd inv_mass = VectorXd::Ones(3);
  const std::vector<Spring> springs{Spring{0, 1, 0.5}, Spring{1, 2, 0.5}};
  SECTION("an empty order is a no-op") {
    const Matrix3Xd start = x;
    gauss_seidel_sweep(x, inv_mass, springs, {});
    REQUIRE(cl::test::near(x, start, 0.0, "particle"));
  }
  SECTION("throws") {
    REQUIRE_THROWS_AS(gauss_seidel_sweep(x, VectorXd::Ones(2), springs, {0, 1}), std::invalid_argument);
    REQUIRE_THROWS_AS(gauss_seidel_sweep(x, inv_mass, springs, {0, 2}), std::invalid_argument);
    REQUIRE_THROWS_AS(gauss_seidel_sweep(x, inv_mass, springs, {-1}), std::invalid_argument);
  }
}
