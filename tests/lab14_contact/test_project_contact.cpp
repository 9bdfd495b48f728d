// TODO(lab14.2): the one-sided contact projection of one particle.
#include <cmath>
#include <stdexcept>

#include "tests/support/catch.h"

#include "contact.h"
#include "tests/support/checks.h"

TEST_CASE("project contact puts a penetrating particle on the contact plane", "[lab14][pts=2]") {
  const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 2.0, -2.0) / 3.0;
  const Eigen::Vector3d point(0.5, -0.25, 1.0);
  for (const double w : {1e-3, 1.0, 1e3}) {
    for (const double depth : {1e-9, 0.3, 7.0}) {
      const Eigen::Vector3d tangent = Eigen::Vector3d(2.0, -1.0, 0.0) / std::sqrt(5.0);  // ⟂ normal
      const Eigen::Vector3d p = point + 0.7 * tangent - depth * normal;
      CAPTURE(w, depth);
      const cl::lab14::ContactProjection projection = cl::lab14::project_contact(p, w, normal, point);
      CHECK(cl::test::near(projection.depth, depth, 1e-15 * (1.0 + depth), "depth"));
      CHECK(cl::test::near(projection.dx, Eigen::Vector3d(depth * normal), 1e-15 * (1.0 + depth), "dx"));
      // Whatever the mass: the collider is immovable (inverse mass 0), the particle takes it all.
      CHECK(cl::test::near(normal.dot(p + projection.dx - point), 0.0, 1e-14, "C after the move"));
    }
  }
}

TEST_CASE("project contact never pulls and never moves a pinned particle", "[lab14][pts=1]") {
  const Eigen::Vector3d normal(0.0, 1.0, 0.0);
  const Eigen::Vector3d point(0.0, 0.0, 0.0);
  for (const double height : {0.0, 1e-12, 0.5}) {
    CAPTURE(height);
    const cl::lab14::ContactProjection free = cl::lab14::project_contact(Eigen::Vector3d(0.3, height, 0.1), 1.0, normal, point);
    CHECK(cl::test::near(free.dx, Eigen::Vector3d::Zero(), 0.0, "dx of a particle on the free side"));
    CHECK(cl::test::near(free.depth, 0.0, 0.0, "depth of a particle on the free side"));
  }
  const cl::lab14::ContactProjection pinned = cl::lab14::project_contact(Eigen::Vector3d(0.0, -0.5, 0.0), 0.0, normal, point);
  CHECK(cl::test::near(pinned.dx, Eigen::Vector3d::Zero(), 0.0, "dx of a pinned particle"));
  CHECK(cl::test::near(pinned.depth, 0.0, 0.0, "depth of a pinned particle"));
  CHECK_THROWS_AS(cl::lab14::project_contact(Eigen::Vector3d::Zero(), 1.0, Eigen::Vector3d(0.0, 2.0, 0.0), point),
                  std::invalid_argument);
  CHECK_THROWS_AS(cl::lab14::project_contact(Eigen::Vector3d::Zero(), -1.0, normal, point), std::invalid_argument);
}
