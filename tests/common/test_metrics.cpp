// Strain and energy measures on cases with known answers.
#include "tests/support/catch.h"

#include "common/metrics.h"

using Catch::Matchers::WithinRel;

TEST_CASE("strain error: relative, absolute for rest length 0", "[common][metrics]") {
  Eigen::Matrix3Xd x(3, 3);
  x << 0, 2, 2,
       0, 0, 1,
       0, 0, 0;
  std::vector<cl::Spring> springs{{0, 1, 1.0}, {1, 2, 1.0}, {0, 2, 0.0}};
  CHECK(cl::strain_error(x, springs[0]) == 1.0);
  CHECK(cl::strain_error(x, springs[1]) == 0.0);
  CHECK_THAT(cl::strain_error(x, springs[2]), WithinRel(std::sqrt(5.0), 1e-15));
  const cl::StrainStats stats = cl::strain_stats(x, {springs[0], springs[1]});
  CHECK(stats.max == 1.0);
  CHECK_THAT(stats.rms, WithinRel(std::sqrt(0.5), 1e-15));
  CHECK(cl::strain_stats(x, {}).max == 0.0);
}

TEST_CASE("strain stats keep a NaN visible", "[common][metrics]") {
  Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, 2);
  x(0, 1) = std::nan("");
  CHECK(std::isnan(cl::strain_stats(x, {{0, 1, 1.0}}).max));
}

TEST_CASE("energies and momentum skip pinned particles", "[common][metrics]") {
  cl::Particles particles;
  particles.x = Eigen::Matrix3Xd::Zero(3, 2);
  particles.x(1, 0) = 2.0;
  particles.x(1, 1) = 5.0;
  particles.v = Eigen::Matrix3Xd::Ones(3, 2);
  particles.inv_mass = Eigen::VectorXd{{0.5, 0.0}};
  CHECK_THAT(cl::kinetic_energy(particles), WithinRel(3.0, 1e-15));
  CHECK_THAT(cl::potential_energy(particles, Eigen::Vector3d(0, -10, 0)), WithinRel(40.0, 1e-15));
  CHECK(cl::linear_momentum(particles) == Eigen::Vector3d(2, 2, 2));
}
