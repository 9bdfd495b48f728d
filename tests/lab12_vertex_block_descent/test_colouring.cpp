// Graded tests of lab12.4: the greedy colouring is valid, deterministic and greedy.
#include <algorithm>
#include <random>
#include <set>

#include "tests/support/catch.h"

#include "scenes.h"
#include "tests/support/checks.h"
#include "vbd.h"

namespace {

void require_valid(const std::vector<int>& colours, int n, const std::vector<cl::Spring>& springs) {
  REQUIRE(static_cast<int>(colours.size()) == n);
  for (std::size_t e = 0; e < springs.size(); ++e) {
    CAPTURE(e, springs[e].i, springs[e].j);
    REQUIRE(colours[static_cast<std::size_t>(springs[e].i)] != colours[static_cast<std::size_t>(springs[e].j)]);
  }
  // Greedy: each particle's colour is the smallest not taken by a neighbour of lower index.
  for (int p = 0; p < n; ++p) {
    std::set<int> below;
    for (const cl::Spring& s : springs) {
      if (s.i == p && s.j < p) below.insert(colours[static_cast<std::size_t>(s.j)]);
      if (s.j == p && s.i < p) below.insert(colours[static_cast<std::size_t>(s.i)]);
    }
    int smallest = 0;
    while (below.count(smallest)) ++smallest;
    CAPTURE(p);
    REQUIRE(colours[static_cast<std::size_t>(p)] == smallest);
  }
}

}  // namespace

TEST_CASE("the greedy colouring is valid and smallest-first and deterministic and has 4 colours on a sheared grid",
          "[lab12][pts=2]") {
  // A chain alternates two colours; a triangle needs three.
  REQUIRE(cl::lab12::colour_particles(5, {{0, 1, 1.0, 1.0}, {1, 2, 1.0, 1.0}, {2, 3, 1.0, 1.0}, {3, 4, 1.0, 1.0}}) ==
          std::vector<int>{0, 1, 0, 1, 0});
  REQUIRE(cl::lab12::colour_particles(3, {{0, 1, 1.0, 1.0}, {2, 1, 1.0, 1.0}, {0, 2, 1.0, 1.0}}) ==
          std::vector<int>{0, 1, 2});
  REQUIRE(cl::lab12::colour_particles(3, {}) == std::vector<int>{0, 0, 0});
  std::mt19937_64 rng(1204);
  for (int trial = 0; trial < 6; ++trial) {
    const cl::Particles particles = lab12_test::random_particles(rng, 30);
    const std::vector<cl::Spring> springs = lab12_test::random_springs(rng, particles.x, 40, 0.8, 1.2, 0.0, 1.0);
    const std::vector<int> colours = cl::lab12::colour_particles(30, springs);
    CAPTURE(trial);
    require_valid(colours, 30, springs);
    REQUIRE(cl::lab12::colour_particles(30, springs) == colours);  // the same again
  }
  // Structural and shear springs make every 2 × 2 block a clique (≥ 4
  // colours); row-major greedy tiles the grid with exactly 4.
  for (const int size : {2, 5, 16}) {
    const std::vector<cl::Spring> springs = lab12_test::grid_springs(size, size, 0.1, 1.0, true);
    const std::vector<int> colours = cl::lab12::colour_particles(size * size, springs);
    CAPTURE(size);
    require_valid(colours, size * size, springs);
    REQUIRE(*std::max_element(colours.begin(), colours.end()) + 1 == 4);
  }
  REQUIRE_THROWS_AS(cl::lab12::colour_particles(2, {{0, 2, 1.0, 1.0}}), std::invalid_argument);
  REQUIRE_THROWS_AS(cl::lab12::colour_particles(2, {{1, 1, 1.0, 1.0}}), std::invalid_argument);
}
