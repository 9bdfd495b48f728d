// The frame loops' shared verdicts: common/window_means.h (has the run settled?)
// and common/health.h's energy_rise_problem (has the solver pumped energy in?).
#include <cmath>
#include <stdexcept>
#include <string>

#include "tests/support/catch.h"

#include "common/health.h"
#include "common/window_means.h"

using cl::test::ContainsText;
using Catch::Matchers::WithinRel;

TEST_CASE("a constant series settles after exactly three windows", "[common][frames]") {
  for (const int window : {1, 4, 60}) {
    for (const double value : {2.5, -0.75}) {
      CAPTURE(window, value);
      cl::WindowMeans means(window);
      for (int w = 1; w <= 5; ++w) {
        for (int f = 1; f <= window; ++f) {
          CAPTURE(w, f);
          REQUIRE(means.add(value) == (f == window));
        }
        CHECK(means.windows_done() == w);
        CHECK_THAT(means.last(), WithinRel(value, 1e-15));
        CHECK(means.settled(1e-12) == (w >= 3));
        CHECK(means.relative_spread() == (w >= 3 ? 0.0 : -1.0));
      }
    }
  }
}

TEST_CASE("a linear ramp never settles below its spread and settles at it", "[common][frames]") {
  // v_f = a + b f: the window means step by b W, so the last three span 2 b W.
  const int window = 6;
  const double a = 1.0, b = 0.125;
  const int windows = 40;
  // Below the relative spread of the last window, which is the smallest (the means grow).
  const double below_all = 0.99 * 2.0 * b * window / (a + b * (windows * window - 0.5 * (window - 1)));
  cl::WindowMeans means(window);
  bool ever_settled = false;
  for (int f = 1; f <= windows * window; ++f) {
    if (!means.add(a + b * f)) continue;
    ever_settled = ever_settled || means.settled(below_all);
    const int k = f / window;
    const double mean = a + b * (f - 0.5 * (window - 1));  // the window's middle frame
    const double relative = 2.0 * b * window / mean;
    CAPTURE(f, k, mean, relative);
    CHECK_THAT(means.last(), WithinRel(mean, 1e-14));
    if (k < 3) {
      CHECK(means.relative_spread() == -1.0);
      CHECK_FALSE(means.settled(1e6));
      continue;
    }
    CHECK_THAT(means.relative_spread(), WithinRel(relative, 1e-12));
    CHECK_FALSE(means.settled(relative * (1.0 - 1e-9)));
    CHECK(means.settled(relative * (1.0 + 1e-9)));
  }
  CHECK(means.windows_done() == windows);
  CHECK_FALSE(ever_settled);
}

TEST_CASE("window means: zero tolerance never settles, a zero series does", "[common][frames]") {
  cl::WindowMeans zeros(2), jumps(1);
  for (int f = 0; f < 6; ++f) zeros.add(0.0);
  CHECK(zeros.relative_spread() == 0.0);
  CHECK(zeros.settled(0.01));
  CHECK_FALSE(zeros.settled(0.0));
  for (const double value : {1.0, -1.0, 0.0}) jumps.add(value);  // spread around a zero last mean
  CHECK(jumps.relative_spread() == 1.0);
  CHECK_FALSE(jumps.settled(1e6));
  CHECK_THROWS_AS(cl::WindowMeans(0), std::invalid_argument);
}

TEST_CASE("energy rise verdict: silent up to the scale, names both numbers above it", "[common][health]") {
  CHECK(cl::energy_rise_problem(3.0, 3.0).empty());
  CHECK(cl::energy_rise_problem(-5.0, 3.0).empty());
  CHECK(cl::energy_rise_problem(std::nan(""), 3.0).empty());
  CHECK(cl::energy_rise_problem(4.25, 3.0) ==
        "total energy rose 4.25 J above its start (more than the scene's 3 J): unstable");
  CHECK(cl::energy_rise_problem(1.23456e7, 0.5, "kinetic + potential energy") ==
        "kinetic + potential energy rose 1.23e+07 J above its start (more than the scene's 0.5 J): unstable");
  const std::string long_name(300, 'e');
  CHECK_THAT(cl::energy_rise_problem(2.0, 1.0, long_name), ContainsText(long_name + " rose 2 J"));
}

TEST_CASE("energy rise verdict: a scale of 0 or less turns it off", "[common][health]") {
  for (const double scale : {0.0, -1.0, std::nan("")}) {
    CAPTURE(scale);
    CHECK(cl::energy_rise_problem(1e300, scale).empty());
  }
}
