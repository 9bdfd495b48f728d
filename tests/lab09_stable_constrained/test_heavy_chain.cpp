// Graded test for the whole step (lab09.1–09.4 through the given stable_step):
// a heavy chain, a light bead chain holding a mass 1000 times heavier, at
// Δt = 1/60 s. Without K_g the beads' sideways motion is integrated
// explicitly at a frequency far above 1/Δt and grows every step; with K_g it
// is implicit and stays within what the initial kick can supply.
#include <cmath>
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/metrics.h"
#include "stable_step.h"

namespace {

struct Outcome {
  double max_transverse = 0.0;  // m/s, over the steps that solved
  int steps_done = 0;
  bool all_ok = true;
  std::string problem;
};

// Runs `steps` steps, or until the transverse speed passes `stop_above`.
Outcome run(const cl::Scene& chain, const cl::lab09::StableSettings& settings, int steps, double stop_above) {
  cl::Particles particles = chain.particles;
  const cl::MovableMap map = cl::make_movable_map(particles.inv_mass);
  Eigen::VectorXd lambda;
  Outcome outcome;
  for (int s = 1; s <= steps; ++s) {
    const cl::lab09::StableStepResult result = cl::lab09::stable_step(particles, chain.springs, map, settings, lambda);
    if (!result.ok || !cl::all_finite(particles.v)) {
      outcome.all_ok = false;
      outcome.problem = result.problem;
      break;
    }
    lambda = result.lambda;
    outcome.max_transverse = std::max(outcome.max_transverse, cl::lab09::max_transverse_speed(particles, chain.springs));
    outcome.steps_done = s;
    if (outcome.max_transverse > stop_above) break;
  }
  return outcome;
}

}  // namespace

TEST_CASE("a heavy chain of mass ratio 1000 at dt 1/60 keeps its transverse speed bounded with K_g and not without",
          "[lab09][pts=3]") {
  // Nine 1 kg beads on 10 links of 0.1 m holding 1000 kg; the beads kicked
  // sideways at ±1 cm/s. The kick's kinetic energy, 9 × ½ × 1 kg × (0.01 m/s)²,
  // is all the sideways motion can ever have (hanging at rest is the energy
  // minimum and the step does not add energy), so no bead can move sideways
  // faster than √(2 E / 1 kg) = 0.03 m/s, nor a link turn faster than twice that.
  // Without K_g the beads vibrate at ω ≈ 2√(T/(mℓ)) ≈ 600 rad/s, ωΔt ≈ 10 ≫ 2.
  const double kick = 0.01;
  const double bound = 2.0 * std::sqrt(9.0) * kick;
  struct Variant {
    const char* name;
    double stiffness;
    cl::lab07::Method method;
  };
  const Variant variants[] = {{"hard links, Schur (dual)", cl::kInfiniteStiffness, cl::lab07::Method::kSchur},
                              {"hard links, KKT", cl::kInfiniteStiffness, cl::lab07::Method::kKkt},
                              {"1e8 N/m springs, Schur (primal)", 1e8, cl::lab07::Method::kSchur}};
  for (const Variant& variant : variants) {
    const cl::Scene chain = cl::lab09::heavy_chain(10, 0.1, 1.0, 1000.0, variant.stiffness, kick);
    cl::lab09::StableSettings settings;
    settings.step.dt = 1.0 / 60.0;
    settings.step.gravity = chain.gravity;
    settings.step.method = variant.method;
    CAPTURE(variant.name, bound);

    settings.geometric_stiffness = true;
    const Outcome with = run(chain, settings, 300, 1e300);
    CAPTURE(with.problem, with.steps_done, with.max_transverse);
    REQUIRE(with.all_ok);
    REQUIRE(with.steps_done == 300);
    REQUIRE(with.max_transverse <= bound);

    settings.geometric_stiffness = false;
    const Outcome without = run(chain, settings, 60, 100.0 * kick);
    CAPTURE(without.problem, without.steps_done, without.max_transverse);
    // Growth: past 100 times the kick within 60 steps (1 s), or so far that
    // the solve gives up on a non-finite state.
    REQUIRE((without.max_transverse > 100.0 * kick || !without.all_ok));
  }
}
