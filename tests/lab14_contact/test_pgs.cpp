// TODO(lab14.4): one projected Gauss-Seidel update of a contact's rows.
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "tests/support/catch.h"

#include "contact.h"
#include "lab14_scenes.h"
#include "tests/support/checks.h"

namespace {

cl::lab14::Contact floor_contact(double mu) {
  cl::lab14::Contact contact;
  contact.normal = Eigen::Vector3d(0.0, 1.0, 0.0);
  contact.point = Eigen::Vector3d::Zero();
  contact.friction = mu;
  return contact;
}

}  // namespace

TEST_CASE("pgs update of a resting particle gives the weight and no gap", "[lab14][pts=2]") {
  const double dt = lab14_test::kDt, g = lab14_test::kG;
  for (const double mass : {1e-3, 2.0, 500.0}) {
    CAPTURE(mass);
    // At rest on the floor: v + Δtg is the free velocity; the normal row must cancel it.
    Eigen::Vector3d velocity(0.0, -g * dt, 0.0);
    cl::lab14::ContactMultipliers lambda;
    cl::lab14::contact_pgs_update(Eigen::Vector3d(0.4, 0.0, -0.2), 1.0 / mass, dt, floor_contact(0.5), lambda, velocity);
    CHECK(cl::test::near_rel(lambda.normal, mass * g, 1e-12, "λ_n (N): the weight"));
    CHECK(cl::test::near(velocity, Eigen::Vector3d::Zero(), 1e-15, "v_new"));
    CHECK(cl::test::near(lambda.tangent, Eigen::Vector3d::Zero(), 1e-15 * mass, "λ_t"));
  }
}

TEST_CASE("pgs update never pulls and keeps the cone", "[lab14][pts=2]") {
  const double dt = 0.01;
  std::srand(1414);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d x = Eigen::Vector3d::Random() * 0.01;
    const Eigen::Vector3d v0 = Eigen::Vector3d::Random() * 2.0;
    const double w = 0.5 + std::abs(Eigen::Vector3d::Random()[0]);
    const double mu = 2.0 * std::abs(Eigen::Vector3d::Random()[0]);
    CAPTURE(trial, x.transpose(), v0.transpose(), w, mu);
    cl::lab14::Contact contact = floor_contact(mu);
    cl::lab14::ContactMultipliers lambda;
    Eigen::Vector3d velocity = v0;
    cl::lab14::contact_pgs_update(x, w, dt, contact, lambda, velocity);
    const double gap = x.y() + dt * velocity.y();
    CHECK(cl::test::at_least("λ_n", lambda.normal, 0.0));
    CHECK(cl::test::at_least("gap at the end of the step", gap, -1e-15));
    CHECK(cl::test::near(gap * lambda.normal, 0.0, 1e-12, "gap · λ_n (complementarity)"));
    CHECK(cl::test::at_most("‖λ_t‖ − μ λ_n", lambda.tangent.norm() - mu * lambda.normal, 1e-12));
    // The velocity is v0 plus Δt w times the force of the rows (Jᵀλ).
    const Eigen::Vector3d force = lambda.normal * contact.normal + lambda.tangent;
    CHECK(cl::test::near(velocity, Eigen::Vector3d(v0 + dt * w * force), 1e-12, "v_new vs v + Δt w Jᵀλ"));
    if (x.y() + dt * v0.y() >= 0.0) {
      CHECK(cl::test::near(velocity, v0, 0.0, "a separating particle keeps its velocity"));
    }
  }
}

TEST_CASE("pgs update slides at mu times the normal force and sticks inside the cone", "[lab14][pts=1]") {
  const double dt = lab14_test::kDt, g = lab14_test::kG;
  // Moving along +x at 1 m/s on the floor: kinetic, λ_t = −μ m g x̂.
  Eigen::Vector3d velocity(1.0, -g * dt, 0.0);
  cl::lab14::ContactMultipliers lambda;
  cl::lab14::contact_pgs_update(Eigen::Vector3d::Zero(), 0.5, dt, floor_contact(0.4), lambda, velocity);
  CHECK(cl::test::near(lambda.tangent, Eigen::Vector3d(-0.4 * 2.0 * g, 0.0, 0.0), 1e-12, "λ_t sliding"));
  CHECK(cl::test::near(velocity.x(), 1.0 - 0.4 * g * dt, 1e-14, "v_x after one step of kinetic friction"));
  // Slow enough to stop within the step: static, no tangential velocity left, never reversed.
  velocity = Eigen::Vector3d(0.01, -g * dt, 0.02);
  lambda = cl::lab14::ContactMultipliers{};
  cl::lab14::contact_pgs_update(Eigen::Vector3d::Zero(), 0.5, dt, floor_contact(0.4), lambda, velocity);
  CHECK(cl::test::near(velocity, Eigen::Vector3d::Zero(), 1e-15, "v_new sticking"));
  CHECK(cl::test::at_most("‖λ_t‖ − μ λ_n", lambda.tangent.norm() - 0.4 * lambda.normal, 0.0));
  // Pinned: nothing changes.
  velocity = Eigen::Vector3d(0.0, -1.0, 0.0);
  lambda = cl::lab14::ContactMultipliers{};
  cl::lab14::contact_pgs_update(Eigen::Vector3d::Zero(), 0.0, dt, floor_contact(0.4), lambda, velocity);
  CHECK(cl::test::near(velocity, Eigen::Vector3d(0.0, -1.0, 0.0), 0.0, "pinned velocity"));
  CHECK(cl::test::near(lambda.normal, 0.0, 0.0, "pinned λ_n"));
  CHECK_THROWS_AS(cl::lab14::contact_pgs_update(Eigen::Vector3d::Zero(), 1.0, 0.0, floor_contact(0.4), lambda, velocity),
                  std::invalid_argument);
}

TEST_CASE("pgs update clamps the accumulated lambda_n: a warm lambda_n falls when the contact opens",
          "[lab14][pts=1]") {
  // A warm start (the previous sweep's λ_n) whose push is no longer needed: the
  // new λ_n is max(0, λ_n − r_n/A), which can be smaller than the old one. A
  // clamp on the increment, λ_n + max(0, −r_n/A), can only keep or raise it.
  const double dt = lab14_test::kDt, w = 1.0, a = dt * dt * w;
  const Eigen::Vector3d x(0.0, 0.01, 0.0);  // 1 cm above the floor
  for (const double warm : {5.0, 200.0}) {
    CAPTURE(warm);
    Eigen::Vector3d velocity(0.0, 1.0, 0.0);  // leaving the floor at 1 m/s, with the warm force in it
    const double gap = x.y() + dt * velocity.y();
    const double expected = std::max(0.0, warm - gap / a);
    cl::lab14::ContactMultipliers lambda;
    lambda.normal = warm;
    cl::lab14::contact_pgs_update(x, w, dt, floor_contact(0.0), lambda, velocity);
    CHECK(cl::test::near(lambda.normal, expected, 1e-12 * warm, "λ_n' = max(0, λ_n − r_n/A) (N)"));
    CHECK(cl::test::near(velocity.y(), 1.0 + dt * w * (expected - warm), 1e-14, "v_y after the update (m/s)"));
  }
}
