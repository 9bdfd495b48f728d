#pragma once
// Matrix comparisons for graded tests: a failure reports the largest
// difference and where it is, never two whole matrices (docs/DESIGN.md §4).
//
//   REQUIRE(cl::test::difference(parallel, serial) == 0.0);         // the same bits
//   REQUIRE(cl::test::difference(x, expected) <= 1e-12);            // to a tolerance
//
// On failure Catch prints the left side through operator<< below, e.g.
//   "largest |actual - expected| = 3.0517578125e-05 at row 1, column 17 of 3 x 2304
//    (actual 0.25003051757812500, expected 0.25) <= 9.9999999999999998e-13"
// A shape mismatch or a NaN fails every comparison and says so.
#include <cmath>
#include <iomanip>
#include <limits>
#include <ostream>

#include <Eigen/Core>

namespace cl::test {

struct MatrixDifference {
  double largest = 0.0;  // max |actual − expected|; NaN when either holds a NaN there
  Eigen::Index row = -1, col = -1;  // where (−1: the matrices are empty or equal)
  double actual = 0.0, expected = 0.0;
  Eigen::Index rows = 0, cols = 0;                    // actual's shape
  Eigen::Index expected_rows = 0, expected_cols = 0;  // expected's shape
  bool same_shape() const { return rows == expected_rows && cols == expected_cols; }
};

template <typename Actual, typename Expected>
MatrixDifference difference(const Eigen::MatrixBase<Actual>& actual, const Eigen::MatrixBase<Expected>& expected) {
  MatrixDifference result;
  result.rows = actual.rows();
  result.cols = actual.cols();
  result.expected_rows = expected.rows();
  result.expected_cols = expected.cols();
  if (!result.same_shape()) return result;
  // Column-major walk; the first NaN wins, otherwise the largest |difference|.
  for (Eigen::Index c = 0; c < actual.cols(); ++c) {
    for (Eigen::Index r = 0; r < actual.rows(); ++r) {
      const double a = static_cast<double>(actual(r, c));
      const double e = static_cast<double>(expected(r, c));
      const double d = std::abs(a - e);
      if (std::isnan(d) || d > result.largest || (result.row < 0 && a != e)) {
        result.largest = d;
        result.row = r;
        result.col = c;
        result.actual = a;
        result.expected = e;
        if (std::isnan(d)) return result;
      }
    }
  }
  return result;
}

// Comparisons against a tolerance; false for a shape mismatch or a NaN.
inline bool operator==(const MatrixDifference& d, double tolerance) {
  return d.same_shape() && d.largest == tolerance;
}
inline bool operator<=(const MatrixDifference& d, double tolerance) {
  return d.same_shape() && d.largest <= tolerance;
}
inline bool operator<(const MatrixDifference& d, double tolerance) {
  return d.same_shape() && d.largest < tolerance;
}

inline std::ostream& operator<<(std::ostream& out, const MatrixDifference& d) {
  const std::streamsize saved = out.precision(17);
  if (!d.same_shape()) {
    out << "shapes differ: actual " << d.rows << " x " << d.cols << ", expected " << d.expected_rows << " x "
        << d.expected_cols;
  } else if (d.row < 0) {
    out << "no difference in " << d.rows << " x " << d.cols;
  } else {
    if (std::isnan(d.largest)) {
      out << "a NaN";
    } else {
      out << "largest |actual - expected| = " << d.largest;
    }
    out << " at row " << d.row << ", column " << d.col << " of " << d.rows << " x " << d.cols << " (actual "
        << d.actual << ", expected " << d.expected << ")";
  }
  out.precision(saved);
  return out;
}

}  // namespace cl::test
