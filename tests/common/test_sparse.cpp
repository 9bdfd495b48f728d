// Unit tests of common/sparse: the movable map, assembly, and the factor's
// three-coordinate solve against a dense solve.
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include "tests/support/catch.h"

#include "common/sparse.h"

using Catch::Matchers::WithinAbs;

namespace {

// A random sparse SPD matrix: a path Laplacian with random weights plus a positive diagonal.
cl::SparseMatrix random_spd(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> weight(0.1, 10.0);
  std::uniform_int_distribution<int> other(0, n - 1);
  std::vector<cl::Triplet> triplets;
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, i, weight(rng));
  for (int e = 0; e < 3 * n; ++e) {
    const int i = other(rng), j = other(rng);
    if (i == j) continue;
    const double k = weight(rng);
    triplets.emplace_back(i, i, k);
    triplets.emplace_back(j, j, k);
    triplets.emplace_back(i, j, -k);
    triplets.emplace_back(j, i, -k);
  }
  return cl::assemble(n, n, triplets);
}

}  // namespace

TEST_CASE("the movable map skips pinned particles and keeps scene order", "[sparse]") {
  Eigen::VectorXd inv_mass(5);
  inv_mass << 0.0, 1.0, 2.0, 0.0, 0.5;
  const cl::MovableMap map = cl::make_movable_map(inv_mass);
  CHECK(map.unknowns() == 3);
  CHECK(map.unknown_of == std::vector<int>{-1, 0, 1, -1, 2});
  CHECK(map.particle_of == std::vector<int>{1, 2, 4});
  inv_mass[2] = -1.0;
  CHECK_THROWS_AS(cl::make_movable_map(inv_mass), std::invalid_argument);
}

TEST_CASE("gather and scatter are inverse on movable particles and leave pinned ones", "[sparse]") {
  Eigen::VectorXd inv_mass(4);
  inv_mass << 1.0, 0.0, 1.0, 1.0;
  const cl::MovableMap map = cl::make_movable_map(inv_mass);
  const Eigen::Matrix3Xd values = Eigen::Matrix3Xd::Random(3, 4);
  Eigen::Matrix3Xd rebuilt = Eigen::Matrix3Xd::Zero(3, 4);
  cl::scatter_rows(cl::gather_rows(values, map), map, rebuilt);
  CHECK(rebuilt.col(0) == values.col(0));
  CHECK(rebuilt.col(1) == Eigen::Vector3d::Zero());
  CHECK(rebuilt.col(3) == values.col(3));
  Eigen::Matrix3Xd stacked_back = Eigen::Matrix3Xd::Zero(3, 4);
  cl::scatter_stacked(cl::gather_stacked(values, map), map, stacked_back);
  CHECK(stacked_back == rebuilt);
}

TEST_CASE("assembly sums duplicates and rejects bad triplets", "[sparse]") {
  const cl::SparseMatrix a = cl::assemble(2, 2, {{0, 0, 1.0}, {0, 0, 2.0}, {1, 0, -1.0}});
  CHECK(a.coeff(0, 0) == 3.0);
  CHECK(a.coeff(1, 0) == -1.0);
  CHECK(a.coeff(1, 1) == 0.0);
  CHECK_THROWS_AS(cl::assemble(2, 2, {{2, 0, 1.0}}), std::invalid_argument);
  CHECK_THROWS_AS(cl::assemble(2, 2, {{0, 0, std::nan("")}}), std::invalid_argument);
}

TEST_CASE("the one-pass three-coordinate solve equals a dense solve", "[sparse]") {
  std::mt19937_64 rng(7);
  for (const int n : {1, 5, 60, 400}) {
    CAPTURE(n);
    const cl::SparseMatrix a = random_spd(rng, n);
    cl::SpdFactorization factor(cl::SpdBackend::kSimplicial);  // the one-pass solve is Eigen's factor's
    REQUIRE(factor.factor(a));
    const cl::RowsX3 b = cl::RowsX3::Random(n, 3);
    const cl::RowsX3 x = factor.solve3(b);
    const Eigen::MatrixXd dense = Eigen::MatrixXd(a);
    const Eigen::MatrixXd expected = dense.ldlt().solve(Eigen::MatrixXd(b));
    const double scale = expected.cwiseAbs().maxCoeff();
    CHECK_THAT((Eigen::MatrixXd(x) - expected).cwiseAbs().maxCoeff(), WithinAbs(0.0, 1e-10 * scale));
    const Eigen::VectorXd single = factor.solve(b.col(1));
    CHECK_THAT((single - expected.col(1)).cwiseAbs().maxCoeff(), WithinAbs(0.0, 1e-10 * scale));
  }
}

TEST_CASE("a singular or indefinite matrix is refused, not factored into NaN", "[sparse]") {
  // A free path Laplacian: constant vectors are in its null space.
  const cl::SparseMatrix singular =
      cl::assemble(2, 2, {{0, 0, 1.0}, {1, 1, 1.0}, {0, 1, -1.0}, {1, 0, -1.0}});
  cl::SpdFactorization factor;
  CHECK_FALSE(factor.factor(singular));
  CHECK_FALSE(factor.ok());
  CHECK_THROWS_AS(factor.solve3(cl::RowsX3::Zero(2, 3)), std::logic_error);
  const cl::SparseMatrix indefinite = cl::assemble(2, 2, {{0, 0, 1.0}, {1, 1, -1.0}});
  CHECK_FALSE(factor.factor(indefinite));
  CHECK(factor.factorizations() == 2);
}

TEST_CASE("refactor reuses the analysis for the same pattern and falls back for another", "[sparse]") {
  std::mt19937_64 rng(11);
  const cl::SparseMatrix a = random_spd(rng, 80);
  cl::SparseMatrix scaled = a;  // same pattern, other values (still SPD)
  for (Eigen::Index k = 0; k < scaled.nonZeros(); ++k) scaled.valuePtr()[k] *= 1.0 + 0.01 * static_cast<double>(k % 7);
  scaled.diagonal() += Eigen::VectorXd::Constant(80, 50.0);
  const cl::RowsX3 b = cl::RowsX3::Random(80, 3);
  cl::SpdFactorization factor;
  REQUIRE(factor.refactor(a));  // nothing analysed yet: a plain factor()
  REQUIRE(factor.refactor(scaled));
  const Eigen::MatrixXd expected = Eigen::MatrixXd(scaled).ldlt().solve(Eigen::MatrixXd(b));
  CHECK_THAT((Eigen::MatrixXd(factor.solve3(b)) - expected).cwiseAbs().maxCoeff(),
             WithinAbs(0.0, 1e-10 * expected.cwiseAbs().maxCoeff()));
  const cl::SparseMatrix other = random_spd(rng, 80);  // another pattern
  REQUIRE(factor.refactor(other));
  const Eigen::MatrixXd other_expected = Eigen::MatrixXd(other).ldlt().solve(Eigen::MatrixXd(b));
  CHECK_THAT((Eigen::MatrixXd(factor.solve3(b)) - other_expected).cwiseAbs().maxCoeff(),
             WithinAbs(0.0, 1e-10 * other_expected.cwiseAbs().maxCoeff()));
  CHECK(factor.factorizations() == 3);
}
