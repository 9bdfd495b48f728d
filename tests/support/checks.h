#pragma once
// Comparisons for graded tests whose failure leads with what is wrong
// (docs/DESIGN.md §4). Each returns a Check: REQUIRE it, and on a failure
// Catch's expansion — the assertion's own text, which the grader shows before
// any CAPTUREd context — reads
//   |actual − expected| = 3.0517578125000000e-05 > tol 9.9999999999999998e-13
//   at row 1, particle 17 of 3 x 2304 (actual 0.25003051757812500, expected 0.25)
// with every number in 17 significant digits and a matrix reduced to its worst
// entry and where it is, never printed whole.
//
//   REQUIRE(cl::test::near(x, expected, 1e-12));               // a double, to an absolute tolerance
//   REQUIRE(cl::test::near_rel(length, rest, 1e-12));          // tol = 1e-12 · |expected|
//   REQUIRE(cl::test::near(x, expected, 1e-12, "particle"));   // matrices: what a column is
//   REQUIRE(cl::test::at_most("strain", strain, 1e-3));        // a one-sided bound
//   REQUIRE(cl::test::solved(result));                         // result.ok, else result.problem
//   CHECK(cl::test::answer("f(1)", f(1), false, "why"));        // a yes/no answer, with the call and why
//
// (Catch's WithinRel/WithinAbs print "X and Y are within ... of each other" on
// a failure, which reads like a pass; these say the difference and the bound.)
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>

#include <Eigen/Core>

#include "tests/support/matrix_checks.h"

namespace cl::test {

struct Check {
  bool passed = false;
  std::string text;  // what was compared, and on a failure by how much and where
  explicit operator bool() const { return passed; }
};

inline std::ostream& operator<<(std::ostream& out, const Check& check) { return out << check.text; }

// A double in 17 significant digits (round-trips), e.g. 0.10000000000000001.
inline std::string digits(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

namespace detail {

inline std::string prefix(const std::string& what) { return what.empty() ? std::string() : what + ": "; }

inline Check compare(double actual, double expected, double tolerance, const std::string& tolerance_note,
                     const std::string& what) {
  Check check;
  const double d = std::abs(actual - expected);
  check.passed = d <= tolerance;  // false for a NaN anywhere
  const std::string tol = "tol " + digits(tolerance) + tolerance_note;
  if (std::isnan(actual) || std::isnan(expected)) {
    check.text = prefix(what) + "a NaN: actual " + digits(actual) + ", expected " + digits(expected) + " (" + tol + ")";
  } else {
    check.text = prefix(what) + "|actual − expected| = " + digits(d) + (check.passed ? " <= " : " > ") + tol +
                 " (actual " + digits(actual) + ", expected " + digits(expected) + ")";
  }
  return check;
}

}  // namespace detail

// |actual − expected| <= tolerance.
inline Check near(double actual, double expected, double tolerance, const std::string& what = "") {
  return detail::compare(actual, expected, tolerance, "", what);
}

// |actual − expected| <= relative · |expected|.
inline Check near_rel(double actual, double expected, double relative, const std::string& what = "") {
  return detail::compare(actual, expected, relative * std::abs(expected), " = " + digits(relative) + " · |expected|",
                         what);
}

// Every entry within `tolerance`; the text names the worst entry: its row and
// its column (called `column` — "particle", "spring", "constraint" — when a
// column is one of those), the shape, and both values. For a single column
// (one vector), `column` names the vector itself: "particle 17".
template <typename Actual, typename Expected>
Check near(const Eigen::MatrixBase<Actual>& actual, const Eigen::MatrixBase<Expected>& expected, double tolerance,
           const std::string& column = "column") {
  const MatrixDifference d = difference(actual, expected);
  Check check;
  check.passed = d <= tolerance;
  const std::string shape = std::to_string(d.rows) + " x " + std::to_string(d.cols);
  if (!d.same_shape()) {
    check.text = "shapes differ: actual " + shape + ", expected " + std::to_string(d.expected_rows) + " x " +
                 std::to_string(d.expected_cols);
  } else if (d.row < 0) {
    check.text = "no difference in " + shape;
  } else {
    // A single column is one vector: `column` then names it ("particle 17").
    const std::string place = d.cols == 1 && column != "column"
                                  ? " at row " + std::to_string(d.row) + " of " + column
                                  : " at row " + std::to_string(d.row) + ", " + column + " " + std::to_string(d.col) +
                                        " of " + shape;
    const std::string where = place + " (actual " + digits(d.actual) + ", expected " + digits(d.expected) + ")";
    if (std::isnan(d.largest)) {
      check.text = "a NaN" + where + ", tol " + digits(tolerance);
    } else {
      check.text = "|actual − expected| = " + digits(d.largest) + (check.passed ? " <= " : " > ") + "tol " +
                   digits(tolerance) + where;
    }
  }
  return check;
}

// value <= bound, for a residual, an error or a count; `what` names it.
inline Check at_most(const std::string& what, double value, double bound) {
  Check check;
  check.passed = value <= bound;
  check.text = what + " = " + digits(value) + (check.passed ? " <= " : " > ") + digits(bound);
  return check;
}

// value >= bound.
inline Check at_least(const std::string& what, double value, double bound) {
  Check check;
  check.passed = value >= bound;
  check.text = what + " = " + digits(value) + (check.passed ? " >= " : " < ") + digits(bound);
  return check;
}

// A yes/no function's answer: passes when `got` is `expected`; the text is
// "CALL returned true, expected false: WHY" (on a pass "CALL returned false:
// WHY"). For a predicate, so that a failure reads as the call, its answer and
// the reason instead of Catch's expansion of REQUIRE_FALSE(f(...)), "!true".
inline Check answer(const std::string& call, bool got, bool expected, const std::string& why) {
  Check check;
  check.passed = got == expected;
  check.text = call + " returned " + (got ? "true" : "false") +
               (check.passed ? std::string() : std::string(", expected ") + (expected ? "true" : "false")) + ": " +
               why;
  return check;
}

// A solver's result: passes when result.ok, and otherwise says result.problem,
// the solver's own line about what went wrong.
template <typename Result>
Check solved(const Result& result) {
  Check check;
  check.passed = result.ok;
  check.text = result.ok ? std::string("solved") : "not solved: " + result.problem;
  return check;
}

// A result whose `problem` is empty when all went well (a step, a run).
template <typename Result>
Check healthy(const Result& result) {
  Check check;
  check.passed = result.problem.empty();
  check.text = check.passed ? std::string("no problem reported") : "problem: " + result.problem;
  return check;
}

}  // namespace cl::test
