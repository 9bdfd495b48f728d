// Graded tests for lab10.3, solve_hierarchy: the order of the coarse-to-fine
// pass, the one-level case, and bad arguments.
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "common/hierarchy.h"
#include "common/scene.h"
#include "gauss_seidel.h"
#include "hpbd.h"
#include "single_spring.h"

using Catch::Matchers::WithinAbs;
using Eigen::Matrix3Xd;
using Eigen::Vector3d;

namespace {

cl::Scene cloth(int nx, int ny) {
  return cl::parse_scene(R"({"cloth": {"nx": )" + std::to_string(nx) + R"(, "ny": )" + std::to_string(ny) +
                             R"(, "pin": ["top-left", "top-right"]}})",
                         "test-cloth-" + std::to_string(nx) + "x" + std::to_string(ny));
}

// The rest grid stretched by `scale` and shaken by `noise` (m), the pins kept.
Matrix3Xd disturbed(const cl::Scene& scene, double scale, double noise, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Matrix3Xd x = scene.particles.x;
  for (Eigen::Index p = 0; p < x.cols(); ++p) {
    if (scene.particles.inv_mass[p] == 0.0) continue;
    x.col(p) = scale * x.col(p) + noise * Vector3d(unit(rng), unit(rng), unit(rng));
  }
  return x;
}

double largest_difference(const Matrix3Xd& a, const Matrix3Xd& b, Eigen::Index& where) {
  Eigen::VectorXd column = (a - b).cwiseAbs().colwise().maxCoeff().transpose();
  return column.maxCoeff(&where);
}

}  // namespace

TEST_CASE("a three-level solve is coarsest first with unilateral sweeps then prolongation then the cloth",
          "[lab10][pts=2]") {
  std::mt19937_64 rng(1010);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const auto& [nx, ny] : {std::pair<int, int>{9, 7}, {12, 12}}) {
    cl::Scene scene = cloth(nx, ny);
    for (Eigen::Index p = 0; p < scene.particles.size(); ++p) {
      if (scene.particles.inv_mass[p] > 0.0) scene.particles.inv_mass[p] = std::pow(10.0, 2.0 * unit(rng) - 1.0);
    }
    const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
        nx, ny, scene.particles.x, scene.particles.inv_mass, scene.springs, 3);
    const std::vector<int> iterations{2, 3, 1};
    const Matrix3Xd start = disturbed(scene, 1.15, 0.06, rng);

    // The pass written out with lab 01's projection and the prolongation formula.
    Matrix3Xd expected = start;
    int stretched = 0, slack = 0;
    for (int l = 2; l >= 1; --l) {
      const cl::HierarchyLevel& level = hierarchy.levels[static_cast<std::size_t>(l)];
      for (int k = 0; k < iterations[static_cast<std::size_t>(l)]; ++k) {
        for (const cl::Spring& s : level.springs) {
          if ((expected.col(s.i) - expected.col(s.j)).norm() <= s.rest_length) {
            ++slack;
            continue;
          }
          ++stretched;
          const cl::lab01::DistanceCorrection c = cl::lab01::project_distance(
              expected.col(s.i), expected.col(s.j), level.inv_mass[s.i], level.inv_mass[s.j], s.rest_length);
          expected.col(s.i) += c.dx_i;
          expected.col(s.j) += c.dx_j;
        }
      }
      const cl::HierarchyLevel& finer = hierarchy.levels[static_cast<std::size_t>(l - 1)];
      for (const cl::Interpolation& e : finer.prolongation) {
        if (!(finer.inv_mass[e.particle] > 0.0)) continue;
        for (std::size_t k = 0; k < e.parents.size(); ++k) {
          expected.col(e.particle) += e.weights[k] * (expected.col(e.parents[k]) - start.col(e.parents[k]));
        }
      }
    }
    std::vector<int> order(scene.springs.size());
    std::iota(order.begin(), order.end(), 0);
    for (int k = 0; k < iterations[0]; ++k) {
      cl::lab02::gauss_seidel_sweep(expected, scene.particles.inv_mass, scene.springs, order);
    }
    CAPTURE(nx, ny, stretched, slack);
    REQUIRE(stretched > 0);  // the start exercises both branches of the unilateral constraint
    REQUIRE(slack > 0);

    Matrix3Xd x = start;
    cl::lab10::solve_hierarchy(x, hierarchy, iterations);
    Eigen::Index where = 0;
    const double difference = largest_difference(x, expected, where);
    CAPTURE(where, x.col(where), expected.col(where));
    REQUIRE_THAT(difference, WithinAbs(0.0, 1e-12));
  }
}

TEST_CASE("with one level the solve is K Gauss-Seidel sweeps of lab 02 in file order", "[lab10][pts=1]") {
  std::mt19937_64 rng(1011);
  const cl::Scene scene = cloth(10, 8);
  const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
      10, 8, scene.particles.x, scene.particles.inv_mass, scene.springs, 1);
  std::vector<int> order(scene.springs.size());
  std::iota(order.begin(), order.end(), 0);
  for (const int k : {0, 1, 5}) {
    const Matrix3Xd start = disturbed(scene, 1.1, 0.05, rng);
    Matrix3Xd expected = start;
    for (int sweep = 0; sweep < k; ++sweep) {
      cl::lab02::gauss_seidel_sweep(expected, scene.particles.inv_mass, scene.springs, order);
    }
    Matrix3Xd x = start;
    cl::lab10::solve_hierarchy(x, hierarchy, {k});
    Eigen::Index where = 0;
    const double difference = largest_difference(x, expected, where);
    CAPTURE(k, where, x.col(where), expected.col(where));
    REQUIRE_THAT(difference, WithinAbs(0.0, 1e-14));
  }
}

TEST_CASE("solve and prolongation reject bad arguments with invalid_argument", "[lab10][pts=1]") {
  const cl::Scene scene = cloth(9, 9);
  const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
      9, 9, scene.particles.x, scene.particles.inv_mass, scene.springs, 3);
  std::mt19937_64 rng(1012);
  const Matrix3Xd start = disturbed(scene, 1.2, 0.0, rng);
  for (const std::vector<int>& bad : std::vector<std::vector<int>>{{4, 4}, {4, 4, 4, 4}, {4, -1, 4}, {-2, 4, 4}, {}}) {
    CAPTURE(bad);
    Matrix3Xd x = start;
    REQUIRE_THROWS_AS(cl::lab10::solve_hierarchy(x, hierarchy, bad), std::invalid_argument);
    REQUIRE(x == start);  // nothing changed before the throw
  }
  Matrix3Xd too_few = start.leftCols(start.cols() - 1);
  REQUIRE_THROWS_AS(cl::lab10::solve_hierarchy(too_few, hierarchy, {1, 1, 1}), std::invalid_argument);

  const cl::HierarchyLevel& fine = hierarchy.levels[0];
  Matrix3Xd x = start;
  REQUIRE_THROWS_AS(cl::lab10::prolong_corrections(x, start.leftCols(5), fine.prolongation, fine.inv_mass),
                    std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab10::prolong_corrections(x, start, fine.prolongation, fine.inv_mass.head(5)),
                    std::invalid_argument);
  std::vector<cl::Interpolation> broken = fine.prolongation;
  broken.back().parents.push_back(0);  // one parent more than weights
  REQUIRE_THROWS_AS(cl::lab10::prolong_corrections(x, start, broken, fine.inv_mass), std::invalid_argument);
  broken = fine.prolongation;
  broken.front().parents.front() = static_cast<int>(start.cols());  // out of range
  REQUIRE_THROWS_AS(cl::lab10::prolong_corrections(x, start, broken, fine.inv_mass), std::invalid_argument);
  broken = fine.prolongation;
  broken.front().particle = -1;
  REQUIRE_THROWS_AS(cl::lab10::prolong_corrections(x, start, broken, fine.inv_mass), std::invalid_argument);
}
