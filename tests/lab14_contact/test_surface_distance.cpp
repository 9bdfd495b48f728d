// TODO(lab14.1): signed distance and outward normal to a plane, a sphere and a capsule.
#include <cmath>
#include <limits>
#include <stdexcept>

#include "tests/support/catch.h"

#include "contact.h"
#include "lab14_scenes.h"
#include "tests/support/checks.h"

namespace {

// The normal is the gradient of the distance: a central difference of step h
// (error O(h²) where the distance is smooth) must match it.
Eigen::Vector3d distance_gradient(const cl::Collider& collider, const Eigen::Vector3d& x, double h) {
  Eigen::Vector3d gradient;
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(axis);
    gradient[axis] = (cl::lab14::surface_distance(collider, x + step).distance -
                      cl::lab14::surface_distance(collider, x - step).distance) / (2.0 * h);
  }
  return gradient;
}

}  // namespace

TEST_CASE("surface distance of a plane a sphere and a capsule in closed form", "[lab14][pts=2]") {
  using lab14_test::capsule;
  using lab14_test::plane;
  using lab14_test::sphere;
  const cl::Collider floor = plane(Eigen::Vector3d(0.0, -1.0, 0.0), Eigen::Vector3d(0.0, 2.0, 0.0));
  const cl::lab14::SurfacePoint above = cl::lab14::surface_distance(floor, Eigen::Vector3d(3.0, 0.5, -2.0));
  CHECK(cl::test::near(above.distance, 1.5, 1e-15, "plane: distance"));
  CHECK(cl::test::near(above.normal, Eigen::Vector3d(0.0, 1.0, 0.0), 1e-15, "plane: normal"));
  const cl::Collider tilted = plane(Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Vector3d(1.0, 1.0, 0.0));
  CHECK(cl::test::near(cl::lab14::surface_distance(tilted, Eigen::Vector3d(0.0, 0.0, 5.0)).distance,
                       -std::sqrt(0.5), 1e-15, "tilted plane: a point behind it"));

  const cl::Collider ball = sphere(Eigen::Vector3d(1.0, 2.0, 3.0), 0.5);
  const cl::lab14::SurfacePoint out = cl::lab14::surface_distance(ball, Eigen::Vector3d(1.0, 2.0, 5.0));
  CHECK(cl::test::near(out.distance, 1.5, 1e-15, "sphere: distance outside"));
  CHECK(cl::test::near(out.normal, Eigen::Vector3d(0.0, 0.0, 1.0), 1e-15, "sphere: normal"));
  const cl::lab14::SurfacePoint in = cl::lab14::surface_distance(ball, Eigen::Vector3d(0.8, 2.0, 3.0));
  CHECK(cl::test::near(in.distance, -0.3, 1e-15, "sphere: distance inside"));
  CHECK(cl::test::near(in.normal, Eigen::Vector3d(-1.0, 0.0, 0.0), 1e-15, "sphere: normal inside"));

  const cl::Collider rod = capsule(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(2.0, 0.0, 0.0), 0.25);
  const cl::lab14::SurfacePoint side = cl::lab14::surface_distance(rod, Eigen::Vector3d(1.2, 0.0, 1.0));
  CHECK(cl::test::near(side.distance, 0.75, 1e-15, "capsule: beside its axis"));
  CHECK(cl::test::near(side.normal, Eigen::Vector3d(0.0, 0.0, 1.0), 1e-15, "capsule: normal beside its axis"));
  const cl::lab14::SurfacePoint beyond = cl::lab14::surface_distance(rod, Eigen::Vector3d(5.0, 4.0, 0.0));
  CHECK(cl::test::near(beyond.distance, 5.0 - 0.25, 1e-14, "capsule: beyond its end b (a 3-4-5 triangle)"));
  CHECK(cl::test::near(beyond.normal, Eigen::Vector3d(0.6, 0.8, 0.0), 1e-15, "capsule: normal beyond b"));
  const cl::lab14::SurfacePoint before = cl::lab14::surface_distance(rod, Eigen::Vector3d(-0.1, 0.0, 0.0));
  CHECK(cl::test::near(before.distance, -0.15, 1e-15, "capsule: inside the cap at a"));
  const cl::Collider dot = capsule(Eigen::Vector3d(1.0, 1.0, 1.0), Eigen::Vector3d(1.0, 1.0, 1.0), 0.5);
  CHECK(cl::test::near(cl::lab14::surface_distance(dot, Eigen::Vector3d(1.0, 3.0, 1.0)).distance, 1.5, 1e-15,
                       "capsule with a = b: a sphere"));
}

TEST_CASE("surface normal is the gradient of the distance at random points", "[lab14][pts=1]") {
  using lab14_test::capsule;
  using lab14_test::plane;
  using lab14_test::sphere;
  const cl::Collider colliders[] = {plane(Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0.3, 1.0, -0.4)),
                                    sphere(Eigen::Vector3d(0.2, 0.1, -0.3), 0.4),
                                    capsule(Eigen::Vector3d(-0.5, 0.0, 0.1), Eigen::Vector3d(0.6, 0.3, -0.2), 0.2)};
  std::srand(14);
  for (const cl::Collider& collider : colliders) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Vector3d x = 1.5 * Eigen::Vector3d::Random();
      CAPTURE(cl::shape_name(collider.shape), trial, x.transpose());
      const cl::lab14::SurfacePoint surface = cl::lab14::surface_distance(collider, x);
      CHECK(cl::test::near(surface.normal.norm(), 1.0, 1e-12, "|normal|"));
      CHECK(cl::test::near(surface.normal, distance_gradient(collider, x, 1e-6), 1e-6, "normal vs gradient"));
      // The closest surface point x − d n lies on the surface.
      const Eigen::Vector3d foot = x - surface.distance * surface.normal;
      CHECK(cl::test::near(cl::lab14::surface_distance(collider, foot).distance, 0.0, 1e-12, "distance of the foot"));
    }
  }
}

TEST_CASE("surface distance at a sphere centre or on a capsule axis is minus the radius and points up",
          "[lab14][pts=1]") {
  const cl::Collider ball = lab14_test::sphere(Eigen::Vector3d(1.0, 2.0, 3.0), 0.5);
  const cl::lab14::SurfacePoint centre = cl::lab14::surface_distance(ball, Eigen::Vector3d(1.0, 2.0, 3.0));
  CHECK(cl::test::near(centre.distance, -0.5, 0.0, "at the centre: distance"));
  CHECK(cl::test::near(centre.normal, Eigen::Vector3d(0.0, 1.0, 0.0), 0.0, "at the centre: normal"));
  const cl::Collider rod = lab14_test::capsule(Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.0, 0.0, 2.0), 0.25);
  const cl::lab14::SurfacePoint axis = cl::lab14::surface_distance(rod, Eigen::Vector3d(0.0, 0.0, 1.0));
  CHECK(cl::test::near(axis.distance, -0.25, 0.0, "on the axis: distance"));
  CHECK(cl::test::near(axis.normal, Eigen::Vector3d(0.0, 1.0, 0.0), 0.0, "on the axis: normal"));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(cl::lab14::surface_distance(ball, Eigen::Vector3d(nan, 0.0, 0.0)), std::invalid_argument);
}
