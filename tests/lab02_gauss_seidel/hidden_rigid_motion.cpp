// Hidden graded test for lab02.1 (run only by the Gradescope bundle, shown to
// the student after grades are published): a sweep does not care where the
// springs are in space or how they are turned.
#include <random>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "gauss_seidel.h"
#include "tests/support/checks.h"

using cl::Spring;
using Eigen::Matrix3Xd;
using Eigen::Vector3d;
using Eigen::VectorXd;

TEST_CASE("a sweep of a rotated and shifted configuration is the rotated and shifted sweep",
          "[lab02][pts=1][hidden]") {
  // Distance constraints depend only on |x_i - x_j|, so for a rotation R and a
  // shift t:  sweep(R x + t) = R sweep(x) + t, to round-off.
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 10;
    Matrix3Xd x(3, n);
    VectorXd inv_mass(n);
    for (int p = 0; p < n; ++p) {
      x.col(p) = Vector3d(unit(rng), unit(rng), unit(rng));
      inv_mass[p] = p == 0 ? 0.0 : std::pow(10.0, unit(rng));
    }
    std::vector<Spring> springs;
    std::vector<int> order, ends;
    std::vector<double> rest_lengths;
    for (int s = 0; s < 25; ++s) {
      const int i = static_cast<int>(rng() % n);
      const int j = (i + 1 + static_cast<int>(rng() % (n - 1))) % n;
      springs.push_back(Spring{i, j, 0.3 + 0.7 * std::abs(unit(rng))});
      order.push_back(24 - s);
      ends.insert(ends.end(), {i, j});
      rest_lengths.push_back(springs.back().rest_length);
    }
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(3.0 * unit(rng), Vector3d(unit(rng), unit(rng), 1.0).normalized()).toRotationMatrix();
    const Vector3d shift(5.0 * unit(rng), 5.0 * unit(rng), 5.0 * unit(rng));
    CAPTURE(trial, x, inv_mass.transpose(), ends, rest_lengths, order, rotation, shift.transpose());
    Matrix3Xd moved = (rotation * x).colwise() + shift;
    cl::lab02::gauss_seidel_sweep(x, inv_mass, springs, order);
    cl::lab02::gauss_seidel_sweep(moved, inv_mass, springs, order);
    const Matrix3Xd expected = (rotation * x).colwise() + shift;
    REQUIRE(cl::test::near(moved, expected, 1e-12, "particle"));
  }
}
