// The drape scenes: no method's kinetic + potential energy ever rises above
// what the run started with.
#include <algorithm>

#include "tests/support/catch.h"

#include "common/metrics.h"
#include "common/scene.h"
#include "contact_step.h"
#include "lab14_scenes.h"
#include "tests/support/checks.h"

TEST_CASE("a cloth draped over a sphere never has more energy than it started with", "[lab14][pts=2]") {
  using namespace lab14_test;
  // The cloth starts at rest at y = 0 (energy 0) and falls 0.3 m onto the
  // sphere: nothing in the scene can lift it back above its start. 1e-9 J is
  // round-off with room to spare: the energies are sums of 1024 terms of about
  // 1e-3 J each (≈ 1e-16 J of rounding); the first step already takes 0.013 J
  // out of the potential, so a real rise cannot hide under it.
  constexpr double kTolerance = 1e-9;  // J
  cl::Scene loaded = cl::load_scene(cl::resolve_scene_path("drape-sphere", CL_LAB_SCENE_DIR));
  for (const cl::lab14::Method method : kMethods) {
    for (const double mu : {0.0, 0.3}) {
      CAPTURE(cl::lab14::method_name(method), mu);
      cl::Scene scene = loaded;
      cl::lab14::StepSettings settings = settings_for(method);
      settings.friction = mu;
      cl::lab14::ContactStepper stepper(scene, settings);
      const double start = cl::kinetic_energy(scene.particles) + cl::potential_energy(scene.particles, settings.gravity);
      double highest = start;
      int highest_step = 0;
      for (int step = 1; step <= 24; ++step) {
        const cl::lab14::StepReport report = stepper.step(scene.particles);
        REQUIRE(cl::test::healthy(report));
        const double energy =
            cl::kinetic_energy(scene.particles) + cl::potential_energy(scene.particles, settings.gravity);
        if (energy > highest) highest = energy, highest_step = step;
      }
      CAPTURE(highest_step);
      CHECK(cl::test::at_most("highest kinetic + potential − start (J)", highest - start, kTolerance));
    }
  }
}
