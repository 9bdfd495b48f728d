// Graded tests of lab11.4: the restart rule.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "tests/support/catch.h"

#include "acceleration.h"
#include "tests/support/checks.h"

namespace {

// One row of the rule: the objectives, the slack, the expected answer and why.
struct Row {
  double before, after, slack;
  bool restart;
  const char* why;
};

// A failure reads "restart_needed(before 10, after 9, slack 0) returned true,
// expected false: g fell" — the answer and the reason, never Catch's
// expansion of a negated call ("!true").
cl::test::Check answers(const Row& row) {
  const std::string call = "restart_needed(before " + cl::test::digits(row.before) + ", after " +
                           cl::test::digits(row.after) + ", slack " + cl::test::digits(row.slack) + ")";
  return cl::test::answer(call, cl::lab11::restart_needed(row.before, row.after, row.slack), row.restart, row.why);
}

}  // namespace

TEST_CASE("a restart is needed exactly when the objective rises past the slack or is not finite", "[lab11][pts=1]") {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Row rows[] = {
      {10.0, 9.0, 0.0, false, "g fell"},
      {10.0, 10.0, 0.0, false, "g stayed: only a rise restarts"},
      {10.0, 10.5, 0.0, true, "g rose"},
      {10.0, 10.0 + 1e-12, 0.0, true, "g rose and the slack is 0"},
      {10.0, 10.0 + 9e-12, 1e-12, false, "the rise 9e-12 is within slack · |before| = 1e-11"},
      {10.0, 10.0 + 2e-11, 1e-12, true, "the rise 2e-11 is past slack · |before| = 1e-11"},
      {-10.0, -10.0 + 9e-12, 1e-12, false, "the slack is relative to |before|, also for a negative g"},
      {-10.0, -9.0, 1e-12, true, "g rose from a negative value"},
      {0.0, 0.0, 1e-12, false, "g stayed at 0"},
      {0.0, 1e-300, 1e-12, true, "any rise from 0 is past slack · 0"},
      {10.0, nan, 1e-12, true, "a NaN is always a restart, never a silent NaN"},
      {10.0, inf, 1e-12, true, "+inf is always a restart"},
      {10.0, -inf, 1e-12, true, "-inf is always a restart (not finite, although lower)"},
  };
  for (const Row& row : rows) CHECK(answers(row));
  // Refused: objective_before not finite, slack negative or not finite.
  CHECK_THROWS_AS(cl::lab11::restart_needed(nan, 1.0, 0.0), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab11::restart_needed(inf, 1.0, 0.0), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab11::restart_needed(1.0, 1.0, -1e-12), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab11::restart_needed(1.0, 1.0, nan), std::invalid_argument);
  CHECK_THROWS_AS(cl::lab11::restart_needed(1.0, 1.0, inf), std::invalid_argument);
}
