// The pieces the lab drivers share: describe and frames_in (common/scene.h).
#include <climits>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <catch2/catch.hpp>

#include "common/scene.h"

namespace {

cl::Scene parse(const std::string& text) { return cl::parse_scene(text, "test.json"); }

}  // namespace

TEST_CASE("describe counts particles and springs and triangles only when there are some", "[common]") {
  const cl::Scene chain = parse(R"({"name": "rope", "chain": {"links": 5}})");
  CHECK(cl::describe(chain) == "rope (6 particles, 5 springs)");

  const cl::Scene triangle = parse(R"({"name": "tri",
      "particles": [{"x": [0, 0, 0]}, {"x": [1, 0, 0]}, {"x": [0, 1, 0]}],
      "springs": [{"i": 0, "j": 1}, {"i": 1, "j": 2}, {"i": 2, "j": 0}],
      "triangles": [{"i": 0, "j": 1, "k": 2}]})");
  CHECK(cl::describe(triangle) == "tri (3 particles, 3 springs, 1 triangles)");

  for (const int n : {2, 3, 8}) {
    CAPTURE(n);
    const cl::Scene cloth = parse(R"({"name": "cloth", "cloth": {"nx": )" + std::to_string(n) +
                                  R"(, "ny": )" + std::to_string(n) + "}}");
    // A grid of n × n particles has 2 (n − 1)² triangles.
    CHECK(cl::describe(cloth) == "cloth (" + std::to_string(n * n) + " particles, " +
                                     std::to_string(cloth.springs.size()) + " springs, " +
                                     std::to_string(2 * (n - 1) * (n - 1)) + " triangles)");
  }

  const cl::Scene alone = parse(R"({"name": "alone", "particles": [{"x": [0, 0, 0]}]})");
  CHECK(cl::describe(alone) == "alone (1 particles, 0 springs)");
}

TEST_CASE("frames_in rounds seconds over dt to the nearest whole frame", "[common]") {
  for (const double dt : {1.0 / 60.0, 1e-3, 0.25, 0.5}) {
    for (const int frames : {1, 2, 60, 3600}) {
      CAPTURE(dt, frames);
      CHECK(cl::frames_in(frames * dt, dt) == frames);
      CHECK(cl::frames_in((frames + 0.4) * dt, dt) == frames);
      CHECK(cl::frames_in((frames + 0.6) * dt, dt) == frames + 1);
    }
  }
  // An exact half frame (0.625 / 0.25 = 2.5 in binary too) rounds away from zero.
  CHECK(cl::frames_in(0.625, 0.25) == 3);
}

TEST_CASE("frames_in gives at least one frame and at most INT_MAX", "[common]") {
  const double dt = 1.0 / 60.0;
  for (const double seconds : {0.0, -0.0, 0.4 * dt, -1.0, -1e300, -std::numeric_limits<double>::infinity()}) {
    CAPTURE(seconds);
    CHECK(cl::frames_in(seconds, dt) == 1);
  }
  CHECK(cl::frames_in(1e300, dt) == INT_MAX);
  CHECK(cl::frames_in(std::numeric_limits<double>::infinity(), dt) == INT_MAX);
  CHECK(cl::frames_in(1e9, 1e-9) == INT_MAX);
}

TEST_CASE("frames_in refuses a NaN time and a dt that is not finite and positive", "[common]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(cl::frames_in(nan, 0.01), std::invalid_argument);
  for (const double dt : {0.0, -0.01, nan, inf}) {
    CAPTURE(dt);
    CHECK_THROWS_AS(cl::frames_in(1.0, dt), std::invalid_argument);
  }
}
