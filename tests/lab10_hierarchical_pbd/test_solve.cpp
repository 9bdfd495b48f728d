// Graded tests for lab10.3, solve_hierarchy: the order of the coarse-to-fine
// pass (the cloth last, and among the coarse levels coarsest first), the
// start it measures corrections from, the masses of the coarse
// sweeps, the one-level case, and bad arguments. Each mistake of the pass has
// a case that names it; all of them call the student's
// project_unilateral_distance and prolong_corrections (lab10.1, lab10.2).
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/hierarchy.h"
#include "common/scene.h"
#include "gauss_seidel.h"
#include "hpbd.h"
#include "single_spring.h"
#include "tests/support/checks.h"

using Eigen::Matrix3Xd;
using Eigen::Vector3d;

namespace {

cl::Scene square_cloth(int nx, int ny) {
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

// The coarse-to-fine pass written out with lab 01's projection (made
// unilateral here), the prolongation formula and lab 02's sweeps: the
// contract of solve_hierarchy, independent of the student's three functions.
// Counts the coarse projections that found their constraint stretched and slack.
// With from_level_start, each prolongation measures its corrections from the
// start of its own level instead (not the contract: what the order's case
// tolerates so that it judges the order alone).
Matrix3Xd written_pass(const cl::ClothHierarchy& hierarchy, const Matrix3Xd& pass_start,
                       const std::vector<int>& iterations, int& stretched, int& slack, bool from_level_start = false) {
  Matrix3Xd x = pass_start;
  Matrix3Xd start = pass_start;
  for (int l = hierarchy.level_count() - 1; l >= 1; --l) {
    if (from_level_start) start = x;
    const cl::HierarchyLevel& level = hierarchy.levels[static_cast<std::size_t>(l)];
    for (int k = 0; k < iterations[static_cast<std::size_t>(l)]; ++k) {
      for (const cl::Spring& s : level.springs) {
        if ((x.col(s.i) - x.col(s.j)).norm() <= s.rest_length) {
          ++slack;
          continue;
        }
        ++stretched;
        const cl::lab01::DistanceCorrection c = cl::lab01::project_distance(
            x.col(s.i), x.col(s.j), level.inv_mass[s.i], level.inv_mass[s.j], s.rest_length);
        x.col(s.i) += c.dx_i;
        x.col(s.j) += c.dx_j;
      }
    }
    const cl::HierarchyLevel& finer = hierarchy.levels[static_cast<std::size_t>(l - 1)];
    for (const cl::Interpolation& e : finer.prolongation) {
      if (!(finer.inv_mass[e.particle] > 0.0)) continue;
      for (std::size_t k = 0; k < e.parents.size(); ++k) {
        x.col(e.particle) += e.weights[k] * (x.col(e.parents[k]) - start.col(e.parents[k]));
      }
    }
  }
  const cl::HierarchyLevel& cloth = hierarchy.levels.front();
  std::vector<int> order(cloth.springs.size());
  std::iota(order.begin(), order.end(), 0);
  for (int k = 0; k < iterations[0]; ++k) cl::lab02::gauss_seidel_sweep(x, cloth.inv_mass, cloth.springs, order);
  return x;
}

// A cloth with unequal masses (0.1 … 10 times each other), pinned at the top.
cl::Scene uneven_cloth(int nx, int ny, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  cl::Scene scene = square_cloth(nx, ny);
  for (Eigen::Index p = 0; p < scene.particles.size(); ++p) {
    if (scene.particles.inv_mass[p] > 0.0) scene.particles.inv_mass[p] = std::pow(10.0, 2.0 * unit(rng) - 1.0);
  }
  return scene;
}

// Every coarse level given the cloth's own inverse masses at its particles, so
// that which level's masses a sweep uses cannot change the result: the cases
// below that test the order of the pass then test the order alone.
void same_masses_on_every_level(cl::ClothHierarchy& hierarchy) {
  const Eigen::VectorXd& cloth_inv_mass = hierarchy.levels.front().inv_mass;
  for (cl::HierarchyLevel& level : hierarchy.levels) {
    for (const int p : level.particles) level.inv_mass[p] = cloth_inv_mass[p];
  }
}

// solve_hierarchy against written_pass, from a stretched and shaken start.
void check_pass(const cl::ClothHierarchy& hierarchy, const cl::Scene& scene, const std::vector<int>& iterations,
                std::mt19937_64& rng) {
  const Matrix3Xd start = disturbed(scene, 1.15, 0.06, rng);
  int stretched = 0, slack = 0;
  const Matrix3Xd expected = written_pass(hierarchy, start, iterations, stretched, slack);
  CAPTURE(scene.grid_nx, scene.grid_ny, hierarchy.level_count(), iterations, stretched, slack);
  if (iterations.size() > 1 && iterations.back() > 0) {
    REQUIRE(stretched > 0);  // the start exercises both branches of the unilateral constraint
    REQUIRE(slack > 0);
  }
  Matrix3Xd x = start;
  cl::lab10::solve_hierarchy(x, hierarchy, iterations);
  REQUIRE(cl::test::near(x, expected, 1e-12, "particle"));
}

}  // namespace

TEST_CASE("levels are solved coarsest first and the cloth last", "[lab10][pts=1]") {
  // Two levels with sweeps on both: the coarse sweeps and the prolongation
  // come before the cloth's sweeps. (Every level has the cloth's masses here,
  // so the masses cannot matter.)
  std::mt19937_64 rng(1010);
  for (const auto& [nx, ny] : {std::pair<int, int>{9, 7}, {12, 12}}) {
    const cl::Scene scene = uneven_cloth(nx, ny, rng);
    cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
        nx, ny, scene.particles.x, scene.particles.inv_mass, scene.springs, 2);
    same_masses_on_every_level(hierarchy);
    check_pass(hierarchy, scene, {2, 3}, rng);
  }
  // Three and four levels with sweeps on every one: among the coarse levels
  // too the coarsest comes first (fine-to-coarse passes the two-level part).
  // Which start the prolongations measure from is the next case's business:
  // either start passes here, so a failure here is the order of the levels.
  for (const auto& [n, levels] : {std::pair<int, int>{13, 3}, {17, 4}}) {
    const cl::Scene scene = uneven_cloth(n, n, rng);
    cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
        n, n, scene.particles.x, scene.particles.inv_mass, scene.springs, levels);
    REQUIRE(hierarchy.level_count() == levels);
    same_masses_on_every_level(hierarchy);
    std::vector<int> iterations(static_cast<std::size_t>(levels), 2);
    iterations.back() = 3;
    const Matrix3Xd start = disturbed(scene, 1.15, 0.06, rng);
    int stretched = 0, slack = 0;
    const Matrix3Xd from_pass = written_pass(hierarchy, start, iterations, stretched, slack);
    const Matrix3Xd from_level = written_pass(hierarchy, start, iterations, stretched, slack, true);
    Matrix3Xd x = start;
    cl::lab10::solve_hierarchy(x, hierarchy, iterations);
    const cl::test::Check pass = cl::test::near(x, from_pass, 1e-12, "particle");
    const cl::test::Check level = cl::test::near(x, from_level, 1e-12, "particle");
    cl::test::Check order;
    order.passed = pass.passed || level.passed;
    order.text = order.passed ? "the coarsest-first pass"
                              : "not the coarsest-first pass (levels " + std::to_string(levels - 1) +
                                    " … 1, then the cloth), whichever start the corrections are measured from: " +
                                    pass.text;
    CAPTURE(n, levels, iterations, level.text);
    REQUIRE(order);
  }
}

TEST_CASE("each prolongation carries every correction since the pass began not only its own level's",
          "[lab10][pts=1]") {
  // Three levels, sweeps on the two coarse ones only: what the coarsest level
  // moved must still reach the cloth's own particles through level 1, so
  // `start` is taken once, before the coarsest level. (The cloth's masses on
  // every level, as above.)
  std::mt19937_64 rng(1013);
  for (const auto& [nx, ny] : {std::pair<int, int>{9, 9}, {13, 11}}) {
    const cl::Scene scene = uneven_cloth(nx, ny, rng);
    cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
        nx, ny, scene.particles.x, scene.particles.inv_mass, scene.springs, 3);
    same_masses_on_every_level(hierarchy);
    check_pass(hierarchy, scene, {0, 1, 2}, rng);
  }
}

TEST_CASE("the sweeps of a coarse level use that level's own inverse masses", "[lab10][pts=1]") {
  // Two levels, sweeps on the coarse one only: the order of the pass and the
  // start cannot matter, only the masses the coarse projections use —
  // levels[1].inv_mass (a coarse particle carries its neighbourhood's mass),
  // not the cloth's.
  std::mt19937_64 rng(1014);
  for (const auto& [nx, ny] : {std::pair<int, int>{9, 7}, {12, 12}}) {
    const cl::Scene scene = uneven_cloth(nx, ny, rng);
    const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
        nx, ny, scene.particles.x, scene.particles.inv_mass, scene.springs, 2);
    double mass_gap = 0.0;  // the case must be able to tell the two mass vectors apart
    for (const int p : hierarchy.levels[1].particles) {
      mass_gap = std::max(mass_gap, std::abs(hierarchy.levels[1].inv_mass[p] - hierarchy.levels[0].inv_mass[p]));
    }
    REQUIRE(mass_gap > 0.1);
    check_pass(hierarchy, scene, {0, 3}, rng);
  }
}

TEST_CASE("a three-level solve is the written-out pass on a cloth with unequal masses", "[lab10][pts=1]") {
  std::mt19937_64 rng(1015);
  for (const auto& [nx, ny] : {std::pair<int, int>{9, 7}, {12, 12}}) {
    const cl::Scene scene = uneven_cloth(nx, ny, rng);
    const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
        nx, ny, scene.particles.x, scene.particles.inv_mass, scene.springs, 3);
    check_pass(hierarchy, scene, {2, 3, 1}, rng);
  }
}

TEST_CASE("with one level the solve is K Gauss-Seidel sweeps of lab 02 in file order", "[lab10][pts=1]") {
  std::mt19937_64 rng(1011);
  const cl::Scene scene = square_cloth(10, 8);
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
    CAPTURE(k);
    REQUIRE(cl::test::near(x, expected, 1e-14, "particle"));
  }
}

TEST_CASE("solve and prolongation reject bad arguments with invalid_argument", "[lab10][pts=1]") {
  const cl::Scene scene = square_cloth(9, 9);
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
  // Every level's inverse masses have one entry per particle, the coarse
  // levels' too: one entry short or one too many is refused before x changes.
  const Eigen::Index n = start.cols();
  for (std::size_t l = 1; l < hierarchy.levels.size(); ++l) {
    for (const Eigen::Index size : {n - 1, n + 1}) {
      CAPTURE(l, size, n);
      cl::ClothHierarchy resized = hierarchy;
      Eigen::VectorXd& inv_mass = resized.levels[l].inv_mass;
      const Eigen::VectorXd kept = inv_mass;
      inv_mass = Eigen::VectorXd::Ones(size);
      inv_mass.head(std::min(size, n)) = kept.head(std::min(size, n));
      Matrix3Xd x = start;
      REQUIRE_THROWS_AS(cl::lab10::solve_hierarchy(x, resized, {1, 1, 1}), std::invalid_argument);
      REQUIRE(x == start);  // nothing changed before the throw
    }
  }

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
