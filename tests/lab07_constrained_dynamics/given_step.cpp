// Ungraded tests of lab 07's given step ([lab07_given], run on the reference
// by ctest -L unit): the line a step prints when its memory runs out.
#include <string>

#include "tests/support/catch.h"

#include "step.h"

using cl::test::ContainsText;

TEST_CASE("a step out of memory names what ran out, the matrix and its size, and what to try", "[lab07_given]") {
  // A 700 x 700 cloth: 490,000 particles, 2 pinned, and its springs.
  const Eigen::Index unknowns = 3 * (490'000 - 2);
  const Eigen::Index constraints = 2'932'606;
  const std::string kkt = cl::lab07::out_of_memory_problem(cl::lab07::Method::kKkt, unknowns, constraints);
  CHECK_THAT(kkt, ContainsText("out of memory in the KKT solve"));
  const std::string side = std::to_string(unknowns + constraints);
  CHECK_THAT(kkt, ContainsText(side + " x " + side));
  CHECK_THAT(kkt, ContainsText(std::to_string(unknowns) + " velocity unknowns, " + std::to_string(constraints) +
                           " constraints"));
  CHECK_THAT(kkt, ContainsText("a smaller scene") && ContainsText("--method schur"));
  CHECK(kkt.find('\n') == std::string::npos);  // one line on stderr
  const std::string schur = cl::lab07::out_of_memory_problem(cl::lab07::Method::kSchur, unknowns, constraints);
  CHECK_THAT(schur, ContainsText("out of memory in the Schur solve"));
  CHECK_THAT(schur, ContainsText(std::to_string(constraints) + " x " + std::to_string(constraints)));
  CHECK_THAT(schur, ContainsText("a smaller scene") && !ContainsText("--method schur"));
}
