// Unit tests of common/spring_blocks: the fixed pattern of spring blocks
// against the same matrix assembled from triplets.
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include "tests/support/catch.h"

#include "common/spring_blocks.h"

namespace {

// The triplets of +S at (i,i), (j,j) and −S at (i,j), (j,i) over the movable ends.
void add_block_triplets(std::vector<cl::Triplet>& triplets, int a, int b, const Eigen::Matrix3d& block) {
  const int rows[4] = {a, b, a, b};
  const int cols[4] = {a, b, b, a};
  const double sign[4] = {1.0, 1.0, -1.0, -1.0};
  for (int k = 0; k < 4; ++k) {
    if (rows[k] < 0 || cols[k] < 0) continue;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) triplets.emplace_back(3 * rows[k] + r, 3 * cols[k] + c, sign[k] * block(r, c));
    }
  }
}

}  // namespace

TEST_CASE("a spring block matrix equals the triplet assembly of the same blocks", "[spring_blocks]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::uniform_int_distribution<int> particle(0, 11);
  Eigen::VectorXd inv_mass = Eigen::VectorXd::Constant(12, 2.0);
  inv_mass[0] = 0.0;  // pinned
  inv_mass[5] = 0.0;
  const cl::MovableMap map = cl::make_movable_map(inv_mass);
  std::vector<cl::Spring> springs;
  springs.push_back({0, 5, 1.0, 1.0});  // both ends pinned: no block
  springs.push_back({0, 1, 1.0, 1.0});  // one end pinned
  while (springs.size() < 30) {
    const int i = particle(rng), j = particle(rng);
    if (i != j) springs.push_back({i, j, 1.0, 1.0});
  }
  cl::SpringBlockMatrix blocks(map, springs);
  CHECK_FALSE(blocks.has_block(0));
  CHECK(blocks.has_block(1));
  CAPTURE(springs.size());
  for (int refill = 0; refill < 2; ++refill) {  // a refill rewrites every value
    blocks.set_zero();
    std::vector<cl::Triplet> triplets;
    for (int u = 0; u < map.unknowns(); ++u) {
      const double mass = 1.0 + value(rng) * value(rng);
      blocks.add_diagonal(u, mass);
      for (int r = 0; r < 3; ++r) triplets.emplace_back(3 * u + r, 3 * u + r, mass);
    }
    for (std::size_t e = 0; e < springs.size(); ++e) {
      const Eigen::Matrix3d random = Eigen::Matrix3d::NullaryExpr([&] { return value(rng); });
      const Eigen::Matrix3d block = random + random.transpose();
      blocks.add_spring(e, block);
      add_block_triplets(triplets, map.unknown_of[static_cast<std::size_t>(springs[e].i)],
                         map.unknown_of[static_cast<std::size_t>(springs[e].j)], block);
    }
    const cl::SparseMatrix expected = cl::assemble(3 * map.unknowns(), 3 * map.unknowns(), triplets);
    const Eigen::MatrixXd difference = Eigen::MatrixXd(blocks.matrix()) - Eigen::MatrixXd(expected);
    CHECK(difference.cwiseAbs().maxCoeff() <= 1e-14);
    CHECK(blocks.matrix().isCompressed());
  }
}

TEST_CASE("a spring block matrix keeps its pattern when every value is 0", "[spring_blocks]") {
  const Eigen::VectorXd inv_mass = Eigen::VectorXd::Ones(3);
  const cl::MovableMap map = cl::make_movable_map(inv_mass);
  cl::SpringBlockMatrix blocks(map, {{0, 1, 1.0, 1.0}, {1, 2, 1.0, 1.0}});
  blocks.set_zero();
  // Diagonal (3 unknowns: 9 x 9) plus the blocks (0,1), (1,0), (1,2), (2,1), explicit zeros kept.
  CHECK(blocks.matrix().nonZeros() == 3 * 9 + 4 * 9);
  CHECK(blocks.rows() == 9);
  CHECK(blocks.springs() == 2);
}

TEST_CASE("a spring block matrix refuses a spring out of range or joining a particle to itself", "[spring_blocks]") {
  const Eigen::VectorXd inv_mass = Eigen::VectorXd::Ones(3);
  const cl::MovableMap map = cl::make_movable_map(inv_mass);
  CHECK_THROWS_AS(cl::SpringBlockMatrix(map, {{0, 3, 1.0, 1.0}}), std::invalid_argument);
  CHECK_THROWS_AS(cl::SpringBlockMatrix(map, {{1, 1, 1.0, 1.0}}), std::invalid_argument);
  CHECK(cl::SpringBlockMatrix().empty());
}
