// Graded tests for lab05.1 inside the step (given code: simulation.h): a
// spring-limited curtain keeps its springs in the band for the whole run, up
// to the 0.5/K that K Gauss-Seidel sweeps may leave; a stiff curtain that the
// explicit step cannot hold is reported, never a silent NaN, and the limiter
// holds it.
#include <cmath>
#include <string>

#include "tests/support/catch.h"

#include "common/scene.h"
#include "simulation.h"
#include "tests/support/checks.h"

using cl::lab05::Limit;

namespace {

cl::Scene shipped(const char* name) { return cl::load_scene(std::string(CL_LAB_SCENE_DIR) + "/" + name + ".json"); }

cl::lab05::StepSettings settings_for(const cl::Scene& scene, Limit limit, int iterations) {
  cl::lab05::StepSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.limit = limit;
  settings.iterations = iterations;
  return settings;  // the default band [0.9, 1.1]
}

struct Extremes {
  double max = -INFINITY;
  double min = INFINITY;
  int steps = 0;
  bool finite = true;
};

// Runs `steps` steps and records the extreme strains of every step after the first state.
Extremes run(const cl::Scene& scene, Limit limit, int iterations, int steps, cl::lab05::RunResult& result) {
  cl::Particles particles = scene.particles;
  const cl::lab05::LimitedSystem system = cl::lab05::make_limited_system(scene, limit);
  Extremes extremes;
  result = cl::lab05::run_steps(particles, system, settings_for(scene, limit, iterations), steps,
                                limit == Limit::kNone, [&](const cl::lab05::StepRecord& record, const cl::Particles& state) {
                                  if (record.step == 0) return;
                                  if (!record.problem.empty()) return;  // the reported step itself may be anything
                                  extremes.finite = extremes.finite && state.x.allFinite() && state.v.allFinite();
                                  extremes.max = std::max(extremes.max, record.strain.max);
                                  extremes.min = std::min(extremes.min, record.strain.min);
                                  ++extremes.steps;
                                });
  return extremes;
}

}  // namespace

TEST_CASE("a spring-limited curtain stays within the band widened by 0.5 over K for the whole run",
          "[lab05][pts=2]") {
  struct Setting {
    const char* scene;
    int iterations;
    int steps;
  };
  for (const Setting& setting : {Setting{"soft-curtain-32", 5, 400}, Setting{"soft-curtain-32", 20, 400},
                                 Setting{"stiff-curtain-32", 10, 300}}) {
    const cl::Scene scene = shipped(setting.scene);
    const double tolerance = 0.5 / setting.iterations;
    cl::lab05::RunResult result;
    const Extremes extremes = run(scene, Limit::kSprings, setting.iterations, setting.steps, result);
    CAPTURE(setting.scene, setting.iterations, setting.steps, tolerance, result.problem, extremes.max, extremes.min);
    REQUIRE(result.problem.empty());
    REQUIRE(extremes.finite);
    REQUIRE(extremes.steps == setting.steps);
    REQUIRE(extremes.max <= 0.1 + tolerance);
    REQUIRE(extremes.min >= -0.1 - tolerance);
    REQUIRE(extremes.max == result.max_strain);
  }
  // Not vacuous: without the limiter the soft curtain stretches far beyond the band.
  const cl::Scene soft = shipped("soft-curtain-32");
  cl::lab05::RunResult unlimited;
  const Extremes free = run(soft, Limit::kNone, 0, 400, unlimited);
  CAPTURE(free.max, unlimited.problem);
  REQUIRE(unlimited.problem.empty());
  REQUIRE(free.max > 0.3);
}

TEST_CASE("the stiff curtain is reported unstable without a limiter and stays in the band and its energy bound with one",
          "[lab05][pts=1]") {
  const cl::Scene scene = shipped("stiff-curtain-32");
  cl::lab05::RunResult unlimited;
  const Extremes before = run(scene, Limit::kNone, 10, 300, unlimited);
  CAPTURE(unlimited.problem, unlimited.problem_step, before.steps);
  REQUIRE(cl::test::answer("the unlimited run reports a problem", !unlimited.problem.empty(), true,
                          "the explicit step is unstable at k dt^2/m = 1.0"));  // reported ...
  REQUIRE(unlimited.problem_step > 0);
  REQUIRE(unlimited.problem_step < 300);
  REQUIRE(before.finite);                    // ... and every step before it was finite: no silent NaN
  REQUIRE(before.steps == unlimited.problem_step - 1);

  cl::lab05::RunResult limited;
  const Extremes after = run(scene, Limit::kSprings, 10, 300, limited);
  CAPTURE(limited.problem, after.max, after.min);
  REQUIRE(limited.problem.empty());
  REQUIRE(after.finite);
  REQUIRE(after.max <= 0.1 + 0.05);
  REQUIRE(after.min >= -0.1 - 0.05);
  // The limiter is busy: the springs sit at the edges of the band.
  REQUIRE(after.max >= 0.1 - 1e-6);
  // Its energy rises above the scene's scale (the explicit step underneath is
  // unstable), but no further than the scene can release inside the band: the
  // limiter contains it. A limiter that holds the band while it pushes the
  // cloth around lets the energy run past that bound.
  CAPTURE(limited.energy_start, limited.energy_scale, limited.energy_exceeded_step);
  REQUIRE(limited.energy_exceeded_step >= 1);
  REQUIRE(cl::test::at_most("the largest rise of the total energy above its start (J)", limited.max_energy_rise,
                            limited.energy_bound));
  REQUIRE(cl::lab05::energy_contained(limited, true));
}

TEST_CASE("a spring-limited soft curtain never gains energy", "[lab05][pts=1]") {
  // The soft curtain's explicit step is stable (k dt²/m = 0.1), and a correct
  // limiter only takes motion out: each projection is the mass-weighted
  // closest length in the band, so it keeps the centre of mass, and the
  // velocity update removes the stretching velocity it undid. A limiter that
  // holds the band but moves the springs' ends any other way pushes the
  // cloth around and puts energy in, while nothing else in the run looks
  // wrong: its strains are in the band and it reports no problem.
  const cl::Scene scene = shipped("soft-curtain-32");
  cl::lab05::RunResult result;
  run(scene, Limit::kSprings, 10, 300, result);
  CAPTURE(result.energy_start, result.energy_end, result.energy_scale);
  REQUIRE(cl::test::healthy(result));
  REQUIRE(cl::test::at_most("the largest rise of the total energy above its start (J)", result.max_energy_rise,
                            1e-3 * result.energy_scale));
}
