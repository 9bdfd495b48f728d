// Hidden graded test for lab04.1 (run only by the Gradescope bundle, shown to
// the student after grades are published): a free cloth seen from a moving
// frame does the same thing.
#include <random>
#include <string>

#include "tests/support/catch.h"

#include "common/scene.h"
#include "pbd.h"
#include "tests/support/checks.h"

using cl::lab04::PbdSettings;
using cl::lab04::Projection;
using Eigen::Matrix3Xd;
using Eigen::Vector3d;

TEST_CASE("adding one velocity u to every particle of a free cloth only carries it along at u",
          "[lab04][pts=1][hidden]") {
  // Springs depend only on x_i - x_j and gravity is uniform, so with nothing
  // pinned, after n steps:  x(v0 + u) = x(v0) + n dt u  and  v(v0 + u) = v(v0) + u.
  const cl::Scene scene = cl::parse_scene(
      R"({"cloth": {"nx": 6, "ny": 6, "pin": []}, "jitter": {"amplitude": 0.03, "seed": 37}})", "hidden-cloth");
  const cl::lab04::ConstraintSet constraints =
      cl::lab04::make_constraint_set(scene.particles.size(), scene.springs);
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const Projection projection : {Projection::kGaussSeidel, Projection::kJacobi}) {
    cl::Particles rest_frame = scene.particles;
    for (Eigen::Index p = 0; p < rest_frame.size(); ++p) {
      rest_frame.inv_mass[p] = std::pow(10.0, unit(rng));
      rest_frame.v.col(p) = Vector3d(unit(rng), unit(rng), unit(rng));
    }
    const Vector3d u(2.0 * unit(rng), 2.0 * unit(rng), 2.0 * unit(rng));
    cl::Particles moving = rest_frame;
    moving.v.colwise() += u;
    PbdSettings settings;
    settings.projection = projection;
    settings.iterations = 8;
    const int steps = 30;
    CAPTURE(projection == Projection::kJacobi, rest_frame.inv_mass.transpose(), rest_frame.v, u.transpose(),
            settings.dt, settings.iterations, steps);
    for (int step = 0; step < steps; ++step) {
      cl::lab04::pbd_step(rest_frame, constraints, settings);
      cl::lab04::pbd_step(moving, constraints, settings);
    }
    const Matrix3Xd carried = rest_frame.x.colwise() + (steps * settings.dt) * u;
    const Matrix3Xd carried_v = rest_frame.v.colwise() + u;
    REQUIRE(cl::test::near(moving.x, carried, 1e-10, "particle"));
    REQUIRE(cl::test::near(moving.v, carried_v, 1e-8, "particle"));
  }
}
