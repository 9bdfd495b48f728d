// Graded test for lab10.3 on the 64 × 64 curtain: the coarse levels carry the
// low-frequency correction, so one step's projection reaches a strain target
// with far fewer projections than flat Gauss-Seidel. Counts, not times.
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/hierarchy.h"
#include "common/scene.h"
#include "simulation.h"

namespace {

// The shipped flat-curtain-64: 1 m × 1 m, 1 kg, structural and shear
// constraints, pinned at the two top corners, no jitter.
cl::Scene curtain_64() {
  return cl::parse_scene(R"({"name": "flat-curtain-64", "dt": 0.0166666666666666667,
      "cloth": {"nx": 64, "ny": 64, "pin": ["top-left", "top-right"]}})",
                         "flat-curtain-64");
}

cl::lab10::ConvergenceResult converge(const cl::Scene& scene, int levels, double target, int max_sweeps) {
  const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
      scene.grid_nx, scene.grid_ny, scene.particles.x, scene.particles.inv_mass, scene.springs, levels);
  const std::vector<int> iterations(static_cast<std::size_t>(levels), 4);
  return cl::lab10::converge_one_step(scene.particles, hierarchy, scene.dt, scene.gravity, iterations, {target},
                                      max_sweeps);
}

}  // namespace

TEST_CASE("on the 64x64 curtain three levels reach the strain target with a quarter of flat GS projections",
          "[lab10][pts=3]") {
  // The claim, with a margin of 4: HPBD (3 levels, 4 sweeps per level and pass)
  // reaches the target with P projections; flat Gauss-Seidel given 4P
  // projections does not. (The reference needs 5 % of flat GS's count at 5 %
  // and at 1 %: the margin is wide.)
  const cl::Scene scene = curtain_64();
  const long long per_sweep = static_cast<long long>(scene.springs.size());
  for (const double target : {0.05, 0.01}) {
    const cl::lab10::ConvergenceResult hierarchical = converge(scene, 3, target, 20000);
    const cl::lab10::TargetReached& h = hierarchical.targets.front();
    CAPTURE(target, h.reached, h.at.passes, h.at.sweeps, h.at.projections, hierarchical.samples.back().strain.max);
    REQUIRE(h.reached);
    REQUIRE(h.at.projections > h.at.sweeps * per_sweep);  // the coarse levels did work
    const int flat_budget = static_cast<int>(4 * h.at.projections / per_sweep);
    const cl::lab10::ConvergenceResult flat = converge(scene, 1, target, flat_budget);
    const cl::lab10::ConvergenceSample& last = flat.samples.back();
    CAPTURE(flat_budget, last.sweeps, last.projections, last.strain.max);
    REQUIRE(last.sweeps == flat_budget);
    REQUIRE_FALSE(flat.targets.front().reached);
  }
}
