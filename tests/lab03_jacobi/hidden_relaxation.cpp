// Hidden graded test for lab03.1 (run only by the Gradescope bundle, shown to
// the student after grades are published): the relaxation factor scales the
// whole step, on a real cloth and for both averagings.
#include <string>

#include "tests/support/catch.h"

#include "common/scene.h"
#include "jacobi.h"
#include "tests/support/checks.h"

using cl::lab03::Averaging;
using Eigen::Matrix3Xd;

TEST_CASE("the step of one Jacobi sweep is omega times the step with omega = 1",
          "[lab03][pts=1][hidden]") {
  // Every correction is computed from the same x, so omega only scales the sum:
  //   x_next(omega) - x = omega (x_next(1) - x)   for every particle; omega = 0: no change.
  const cl::Scene scene = cl::parse_scene(
      R"({"cloth": {"nx": 7, "pin": ["top-left"], "springs": ["structural", "shear", "bending"]},
          "jitter": {"amplitude": 0.05, "seed": 31}})",
      "hidden-cloth.json");
  const Matrix3Xd& x = scene.particles.x;
  const cl::lab03::Incidence incidence = cl::lab03::build_incidence(x.cols(), scene.springs);
  for (const Averaging averaging : {Averaging::kByCount, Averaging::kNone}) {
    Matrix3Xd full;
    cl::lab03::jacobi_sweep(x, full, scene.particles.inv_mass, scene.springs, incidence, 1.0, averaging);
    const Matrix3Xd full_step = full - x;
    REQUIRE(full_step.norm() > 0.0);
    for (const double omega : {0.0, 0.3, 1.7}) {
      CAPTURE(averaging == Averaging::kByCount, omega);
      Matrix3Xd relaxed;
      cl::lab03::jacobi_sweep(x, relaxed, scene.particles.inv_mass, scene.springs, incidence, omega, averaging);
      const Matrix3Xd step = relaxed - x;
      const Matrix3Xd expected = omega * full_step;
      REQUIRE(cl::test::near(step, expected, 1e-13, "particle"));
    }
  }
}
