// Graded test for lab07.3 (with lab07.4): one linear spring in 1-D, where the
// step has a closed form. A pinned particle at the origin, a bead of mass m at
// x = ℓ > 0 on the x axis, rest length L, stiffness k, no gravity. Then
// φ = ℓ − L, J = [1 0 0], C = 1/k, and the KKT system reduces to
//     m v_new − Δt λ = m v,   Δt v_new + λ/k = −φ
// so v_new = (m v − Δt k φ)/(m + Δt² k) and λ = −k(φ + Δt v_new).
#include <cmath>

#include <catch2/catch.hpp>

#include "step.h"

using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;
using Eigen::Vector3d;

TEST_CASE("a 1-D linear spring steps to v_new = (m v - dt k phi)/(m + dt^2 k) with both methods",
          "[lab07][pts=2]") {
  for (const cl::lab07::Method method : {cl::lab07::Method::kKkt, cl::lab07::Method::kSchur}) {
    for (const double k : {1e-3, 1.0, 250.0, 1e6}) {
      for (const double m : {0.01, 1.0, 300.0}) {
        for (const double dt : {1e-3, 1.0 / 60.0, 0.5}) {
          const double length = 1.7, rest = 1.2, v = -0.8;
          cl::Particles particles;
          particles.x.resize(3, 2);
          particles.x.col(0).setZero();
          particles.x.col(1) = Vector3d(length, 0.0, 0.0);
          particles.v.setZero(3, 2);
          particles.v(0, 1) = v;
          particles.inv_mass.resize(2);
          particles.inv_mass << 0.0, 1.0 / m;
          cl::lab07::StepSettings settings;
          settings.dt = dt;
          settings.gravity.setZero();
          settings.method = method;
          const double phi = length - rest;
          const double v_new = (m * v - dt * k * phi) / (m + dt * dt * k);
          const double lambda = -k * (phi + dt * v_new);
          CAPTURE(method == cl::lab07::Method::kKkt ? "kkt" : "schur", k, m, dt, v_new, lambda);
          const cl::lab07::StepResult result =
              cl::lab07::constrained_step(particles, {cl::Spring{0, 1, rest, k}}, settings);
          REQUIRE(result.ok);
          REQUIRE(result.lambda.size() == 1);
          CHECK_THAT(particles.v(0, 1), WithinRel(v_new, 1e-10));
          CHECK_THAT(result.lambda[0], WithinRel(lambda, 1e-9) || WithinAbs(lambda, 1e-12 * k * length));
          CHECK_THAT(particles.x(0, 1), WithinRel(length + dt * v_new, 1e-12));
          CHECK(particles.x.col(0) == Vector3d::Zero());
          CHECK(particles.v.col(0) == Vector3d::Zero());
          CHECK(particles.x.block<2, 1>(1, 1).isZero(0.0));
          CHECK(particles.v.block<2, 1>(1, 1).isZero(0.0));
        }
      }
    }
  }
}
