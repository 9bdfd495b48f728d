// Graded test for lab07.4: redundant hard constraints. The scene
// redundant-triangle is a rigid triangle hanging from a pinned vertex plus a
// second copy of its bottom link: four hard rows of rank three, so
// Δt² J W Jᵀ is singular at C = 0.
#include <cmath>
#include <string>

#include "tests/support/catch.h"

#include "common/scene.h"
#include "constrained.h"
#include "step.h"
#include "tests/support/checks.h"


TEST_CASE("redundant hard constraints make the Schur matrix singular and the step says so without NaN",
          "[lab07][pts=2]") {
  const cl::Scene scene = cl::load_scene(std::string(CL_LAB_SCENE_DIR) + "/redundant-triangle.json");
  REQUIRE(scene.springs.size() == 4);
  cl::lab07::StepSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);

  // The solve itself refuses, with a reason, and returns no numbers.
  const cl::lab07::LinearizedStep step = cl::lab07::linearize(scene.particles, scene.springs, map, settings);
  const cl::lab07::StepSolution schur = cl::lab07::solve_schur(step);
  CAPTURE(schur.problem);
  REQUIRE_FALSE(schur.ok);
  CHECK(schur.problem.find("singular") != std::string::npos);
  CHECK(schur.velocity.allFinite());
  CHECK(schur.lambda.allFinite());

  // The whole step leaves the state exactly as it was.
  cl::Particles particles = scene.particles;
  const cl::lab07::StepResult result = cl::lab07::constrained_step(particles, scene.springs, map, settings);
  CHECK_FALSE(result.ok);
  CHECK(particles.x == scene.particles.x);
  CHECK(particles.v == scene.particles.v);

  // Regularised (every hard link a 1e9 N/m spring) the step is solvable and the
  // two identical copies of the bottom link (springs 1 and 3) share its force
  // equally: the system is symmetric in them.
  settings.regularization = 1e-9;
  particles = scene.particles;
  const cl::lab07::StepResult regularized = cl::lab07::constrained_step(particles, scene.springs, map, settings);
  CAPTURE(regularized.problem);
  REQUIRE(cl::test::solved(regularized));
  REQUIRE(regularized.lambda.size() == 4);
  CAPTURE(regularized.lambda.transpose());
  CHECK(regularized.lambda.allFinite());
  CHECK(particles.x.allFinite());
  CHECK(cl::test::near_rel(regularized.lambda[1], regularized.lambda[3], 1e-6));
}
