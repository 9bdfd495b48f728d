// Given code (simulation.h's run_steps), not a graded task: a limiter that
// only contains a blow-up says so. A stiff chain (k = 1e6 N/m, Δt = 0.01 s,
// masses 0.1–8 kg, so k Δt²/m up to 1e3: the explicit step is far past its
// limit of ½) stays inside the band under the spring limiter with 200 sweeps,
// and the run goes on; its total energy still rises far above what the scene
// could release, and run_steps reports that in energy_exceeded_step. Without
// the limiter the same run stops (it diverges).
//
// Not graded ([lab05_given], no [lab05] tag): the run uses the student's
// limit_spring, so it fails on the stubs, and it charges nothing to a task.
// `./course grade` does not run it; `./course test` does, as the unit test
// lab05_strain_limiting_given (ctest -L unit, cmake/AddLab.cmake), or run
//     build/bin/lab05_strain_limiting_tests_solution "[lab05_given]"
#include <cmath>
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/output.h"
#include "common/scene.h"
#include "simulation.h"
#include "tests/support/checks.h"

using cl::lab05::Limit;

namespace {

// A horizontal chain of 8 links of 0.1 m pinned at its left end, released in
// gravity; the masses double from 0.1 kg to 6.4 kg and end at 8 kg.
cl::Scene stiff_chain() {
  const double masses[] = {0.1, 0.2, 0.4, 0.8, 1.6, 3.2, 6.4, 8.0};
  std::string json = R"({"name": "stiff-chain", "gravity": [0, -9.81, 0], "dt": 0.01, "steps": 200,
    "particles": [{"x": [0, 0, 0], "pinned": true})";
  for (int p = 1; p <= 8; ++p) {
    json += ", {\"x\": [" + cl::format_double(0.1 * p) + ", 0, 0], \"mass\": " + cl::format_double(masses[p - 1]) + "}";
  }
  json += "], \"springs\": [";
  for (int s = 0; s < 8; ++s) {
    json += std::string(s > 0 ? ", " : "") + "{\"i\": " + std::to_string(s) + ", \"j\": " + std::to_string(s + 1) +
            ", \"rest\": 0.1, \"stiffness\": 1e6}";
  }
  json += "]}";
  return cl::parse_scene(json, "stiff-chain (limiter_verdict.cpp)");
}

cl::lab05::RunResult run(const cl::Scene& scene, Limit limit, int iterations, double& max_strain,
                         double& min_strain) {
  cl::lab05::StepSettings settings;
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.limit = limit;
  settings.iterations = iterations;  // the default band [0.9, 1.1]
  cl::Particles particles = scene.particles;
  const cl::lab05::LimitedSystem system = cl::lab05::make_limited_system(scene, limit);
  const cl::lab05::RunResult result =
      cl::lab05::run_steps(particles, system, settings, scene.steps, limit == Limit::kNone);
  max_strain = result.max_strain;
  min_strain = result.min_strain;
  return result;
}

}  // namespace

TEST_CASE("a stiff chain held only by the spring limiter keeps the band, goes on, and is reported",
          "[lab05_given][limiter]") {
  const cl::Scene scene = stiff_chain();
  double high = 0.0, low = 0.0;
  const cl::lab05::RunResult limited = run(scene, Limit::kSprings, 200, high, low);
  INFO("max energy rise " << limited.max_energy_rise << " J, scale " << limited.energy_scale << " J");
  CHECK(limited.problem.empty());
  CHECK(limited.steps_done == scene.steps);
  // Inside the band [0.9, 1.1] up to the 0.5/K K sweeps may leave.
  const double tolerance = cl::lab05::band_tolerance(200);
  CHECK(high <= 0.1 + tolerance);
  CHECK(low >= -0.1 - tolerance);
  // The energy rose above the scale and the run says where it first did.
  CHECK(limited.max_energy_rise > limited.energy_scale);
  CHECK(limited.energy_exceeded_step >= 1);
  CHECK(limited.energy_exceeded_step <= scene.steps);
  CHECK_THAT(limited.energy_exceeded, cl::test::ContainsText("total energy rose"));

  // The same step without the limiter is stopped, and nothing is "exceeded" on top.
  const cl::lab05::RunResult unlimited = run(scene, Limit::kNone, 200, high, low);
  CHECK(cl::test::answer("the unlimited run reports a problem", !unlimited.problem.empty(), true,
                        "k dt^2/m up to 1e3 is far past the explicit limit"));
  CHECK(unlimited.steps_done < scene.steps);
  CHECK(unlimited.energy_exceeded_step == -1);
}

TEST_CASE("a limited run whose energy stays below the scale reports nothing", "[lab05_given][limiter]") {
  // The same chain, soft (k = 100 N/m: k Δt²/m <= 0.1, a stable explicit step).
  cl::Scene scene = stiff_chain();
  for (cl::Spring& spring : scene.springs) spring.stiffness = 100.0;
  double high = 0.0, low = 0.0;
  const cl::lab05::RunResult limited = run(scene, Limit::kSprings, 200, high, low);
  CHECK(limited.problem.empty());
  CHECK(limited.max_energy_rise <= limited.energy_scale);
  CHECK(limited.energy_exceeded_step == -1);
  CHECK(limited.energy_exceeded.empty());
}

TEST_CASE("a rise of energy is contained only inside the band and within what the band can release",
          "[lab05_given][limiter]") {
  // band_energy: one spring of k = 100 N/m and L = 2 m, band [0.9, 1.2]: the
  // far edge is 0.2 L = 0.4 m away, ½ · 100 · 0.4² = 8 J.
  const std::vector<cl::Spring> springs{{0, 1, 2.0, 100.0}};
  CHECK(cl::test::near(cl::lab05::band_energy(springs, 0.9, 1.2), 8.0, 1e-12, "band_energy (J)"));
  CHECK(cl::test::near(cl::lab05::band_energy({}, 0.9, 1.1), 0.0, 0.0, "band_energy without springs (J)"));

  // A run whose energy rose 20 J, past its 10 J scale, from step 5, with 40 J
  // the scene can release inside the band.
  cl::lab05::RunResult result;
  result.energy_scale = 10.0;
  result.energy_bound = 40.0;
  result.energy_exceeded_step = 5;
  result.max_energy_rise = 20.0;
  CHECK(cl::test::answer("energy_contained(rise 20 J, bound 40 J, band held)",
                         cl::lab05::energy_contained(result, true), true, "the limiter held band and energy"));
  CHECK(cl::test::answer("energy_contained(rise 20 J, bound 40 J, band lost)",
                         cl::lab05::energy_contained(result, false), false, "the band was lost: nothing held it"));
  result.max_energy_rise = 41.0;
  CHECK(cl::test::answer("energy_contained(rise 41 J, bound 40 J, band held)",
                         cl::lab05::energy_contained(result, true), false, "past what the band allows"));
  result.max_energy_rise = 20.0;
  result.problem = "max strain 1e3: unstable";
  CHECK(cl::test::answer("energy_contained(a run that stopped)", cl::lab05::energy_contained(result, true), false,
                         "a run that stopped is reported unstable, not contained"));
  result.problem.clear();
  result.energy_exceeded_step = -1;
  result.max_energy_rise = 5.0;
  CHECK(cl::test::answer("energy_contained(rise 5 J, below the 10 J scale)", cl::lab05::energy_contained(result, true),
                         false, "nothing rose past the scale: nothing to contain"));
}
