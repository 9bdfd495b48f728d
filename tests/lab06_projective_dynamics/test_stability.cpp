// Graded test at the extremes (docs/DESIGN.md §6): every combination stays
// finite or is reported, for projective dynamics and Newton alike.
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/metrics.h"
#include "common/scene.h"
#include "projective_dynamics.h"
#include "simulation.h"
#include "test_scenes.h"

namespace {

// A 10-spring chain pinned at one end, free masses alternating 1 kg and 1,000 t.
cl::Scene mass_ratio_chain() {
  cl::Scene scene = cl::parse_scene(R"({"chain": {"links": 10, "length": 0.1, "stiffness": 1}})", "mass-ratio");
  for (Eigen::Index p = 1; p < scene.particles.size(); ++p) scene.particles.inv_mass[p] = p % 2 == 1 ? 1.0 : 1e-6;
  return scene;
}

// A pinned point and three particles, all at the origin, joined by springs of rest length 0.1 m.
cl::Scene coincident() {
  return cl::parse_scene(R"({"particles": [{"x": [0, 0, 0], "pinned": true}, {"x": [0, 0, 0], "mass": 0.1},
      {"x": [0, 0, 0], "mass": 0.1}, {"x": [0, 0, 0], "mass": 0.1}],
      "springs": [{"i": 0, "j": 1, "rest": 0.1, "stiffness": 1}, {"i": 1, "j": 2, "rest": 0.1, "stiffness": 1},
                  {"i": 2, "j": 3, "rest": 0.1, "stiffness": 1}, {"i": 1, "j": 3, "rest": 0.1, "stiffness": 1}]})",
                         "coincident");
}

}  // namespace

TEST_CASE("projective dynamics and Newton stay finite or report a problem at the extremes", "[lab06][pts=1]") {
  const std::vector<std::pair<std::string, cl::Scene>> scenes{
      {"mass-ratio chain", mass_ratio_chain()}, {"coincident", coincident()}, {"cloth 6x6", lab06_test::cloth(6, 1.0)}};
  for (const auto& [name, scene] : scenes) {
    for (const double stiffness : {1e-3, 1e12}) {
      for (const double dt : {1e-6, 0.5}) {
        for (const cl::lab06::Method method : {cl::lab06::Method::kProjectiveDynamics, cl::lab06::Method::kNewton}) {
          for (const int iterations : {1, 50}) {
            std::vector<cl::Spring> springs = scene.springs;
            for (cl::Spring& spring : springs) spring.stiffness = stiffness;
            cl::Particles particles = scene.particles;
            cl::lab06::Solver solver(cl::lab06::make_problem(particles.inv_mass, springs, dt), method);
            cl::lab06::StepSettings settings;
            settings.gravity = scene.gravity;
            settings.iterations = iterations;
            const cl::lab06::RunResult result = cl::lab06::run_steps(particles, solver, settings, 6);
            CAPTURE(name, stiffness, dt, cl::lab06::method_name(method), iterations, result.steps_done,
                    result.problem);
            // Reported, or finite; and the state handed back is finite either way.
            REQUIRE((!result.problem.empty() || result.steps_done == 6));
            REQUIRE(cl::all_finite(particles.x));
            REQUIRE(cl::all_finite(particles.v));
            REQUIRE(std::isfinite(result.objective));
          }
        }
      }
    }
  }
}
