// Graded tests for lab09.2 and lab09.4: the KKT system with M − Δt²K_g, the
// Schur solve with K_g (primal when every constraint is compliant, dual
// otherwise) against the KKT solve, and the refusal of an indefinite M − Δt²K_g.
// K_g comes from the closed form written out in lab09_scenes.h (not from the
// student's geometric_stiffness), and lab 07's functions are its reference.
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/LU>
#include "tests/support/catch.h"

#include "constrained.h"
#include "geometric_stiffness.h"
#include "lab09_scenes.h"
#include "step.h"
#include "tests/support/checks.h"

using cl::lab09::Compression;

namespace {

// Lab 07's KKT matrix with −Δt²K_g added to its upper-left block, written out
// densely here (not with the student's stiff_kkt_system).
Eigen::MatrixXd expected_kkt(const cl::lab07::LinearizedStep& step, const cl::SparseMatrix& stiffness) {
  Eigen::MatrixXd matrix(cl::lab07::kkt_system(step).matrix);
  const Eigen::Index size = step.velocity.size();
  matrix.topLeftCorner(size, size) -= step.dt * step.dt * Eigen::MatrixXd(stiffness);
  return matrix;
}

cl::lab07::StepSolution dense_kkt_solve(const cl::lab07::LinearizedStep& step, const cl::SparseMatrix& stiffness) {
  const Eigen::MatrixXd matrix = expected_kkt(step, stiffness);
  const Eigen::VectorXd unknowns = matrix.fullPivLu().solve(cl::lab07::kkt_system(step).rhs);
  cl::lab07::StepSolution solution;
  solution.velocity = unknowns.head(step.velocity.size());
  solution.lambda = unknowns.tail(step.phi.size());
  solution.ok = unknowns.allFinite();
  return solution;
}

struct Case {
  lab09_test::RandomScene scene;
  cl::MovableMap map;
  cl::lab07::LinearizedStep step;
  cl::SparseMatrix stiffness;  // K_g from random tensions, kDrop
  const char* kind = "";
};

// kind 0: every constraint compliant (1 … 1e6 N/m); 1: hard chain plus
// compliant extras; 2: every constraint hard (no compliance block).
Case make_case(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> exponent(0.0, 6.0);
  const int kind = static_cast<int>(seed % 3);
  const int n = 3 + static_cast<int>(seed % 6);
  Case c;
  c.kind = kind == 0 ? "all compliant" : kind == 1 ? "mixed" : "all hard";
  auto stiffness = [&](int e) {
    if (kind == 2 || (kind == 1 && e < n - 1)) return cl::kInfiniteStiffness;
    return std::pow(10.0, exponent(rng));
  };
  c.scene = lab09_test::random_scene(rng, n, static_cast<int>(seed % 2), kind == 2 ? 0 : n / 2, stiffness);
  c.map = cl::make_movable_map(c.scene.particles.inv_mass);
  cl::lab07::StepSettings settings;
  settings.dt = seed % 4 == 0 ? 0.1 : 1.0 / 60.0;
  settings.gravity = Eigen::Vector3d(0.1, -9.81, 0.3);
  c.step = cl::lab07::linearize(c.scene.particles, c.scene.springs, c.map, settings);
  std::uniform_real_distribution<double> force(-200.0, 20.0);  // mostly tension
  Eigen::VectorXd lambda(static_cast<Eigen::Index>(c.scene.springs.size()));
  for (Eigen::Index e = 0; e < lambda.size(); ++e) lambda[e] = force(rng);
  c.stiffness = lab09_test::closed_form_stiffness(c.scene.particles.x, c.scene.springs, lambda, c.map, true);
  return c;
}

}  // namespace

TEST_CASE("the stiff KKT system is lab 07's with M minus dt squared K_g in its upper left block", "[lab09][pts=2]") {
  for (std::uint64_t seed = 960; seed < 966; ++seed) {
    const Case c = make_case(seed);
    CAPTURE(seed, c.kind, c.scene.text);
    const cl::lab07::KktSystem system = cl::lab09::stiff_kkt_system(c.step, c.stiffness);
    const Eigen::MatrixXd expected = expected_kkt(c.step, c.stiffness);
    const double scale = expected.cwiseAbs().maxCoeff();
    REQUIRE(cl::test::near(Eigen::MatrixXd(system.matrix), expected, 1e-14 * scale));
    REQUIRE(cl::test::near(system.rhs, cl::lab07::kkt_system(c.step).rhs, 0.0));
  }
  const Case c = make_case(961);
  const cl::SparseMatrix wrong(3, 3);
  REQUIRE_THROWS_AS(cl::lab09::stiff_kkt_system(c.step, wrong), std::invalid_argument);
}

TEST_CASE("the Schur solve with K_g agrees with the KKT solve to 1e-9 and with lab 07 at K_g equal to zero",
          "[lab09][pts=2]") {
  // All compliant (the primal form), hard links plus compliant extras and all
  // hard (the dual form); K_g from tensions up to 200 N; Δt 1/60 s and 0.1 s.
  // Tolerances relative to the largest entry (absolute below 1).
  for (std::uint64_t seed = 970; seed < 982; ++seed) {
    const Case c = make_case(seed);
    CAPTURE(seed, c.kind, c.step.dt, c.scene.text);
    const cl::lab07::StepSolution schur = cl::lab09::solve_stiff_schur(c.step, c.stiffness);
    const cl::lab07::StepSolution kkt = dense_kkt_solve(c.step, c.stiffness);
    CAPTURE(schur.problem);
    REQUIRE(cl::test::solved(schur));
    REQUIRE(cl::test::solved(kkt));
    const double v_scale = std::max(1.0, kkt.velocity.cwiseAbs().maxCoeff());
    const double lambda_scale = std::max(1.0, kkt.lambda.cwiseAbs().maxCoeff());
    CAPTURE(v_scale, lambda_scale);
    REQUIRE(cl::test::near(schur.velocity, kkt.velocity, 1e-9 * v_scale));
    REQUIRE(cl::test::near(schur.lambda, kkt.lambda, 1e-9 * lambda_scale));

    const cl::SparseMatrix zero(c.step.velocity.size(), c.step.velocity.size());
    const cl::lab07::StepSolution plain = cl::lab09::solve_stiff_schur(c.step, zero);
    const cl::lab07::StepSolution lab07 = cl::lab07::solve_schur(c.step);
    REQUIRE(cl::test::solved(plain));
    REQUIRE(cl::test::solved(lab07));
    REQUIRE(cl::test::near(plain.velocity, lab07.velocity, 1e-9 * std::max(1.0, lab07.velocity.cwiseAbs().maxCoeff())));
    REQUIRE(cl::test::near(plain.lambda, lab07.lambda, 1e-9 * std::max(1.0, lab07.lambda.cwiseAbs().maxCoeff())));
  }

  SECTION("no springs: v_new = v + dt g") {
    cl::lab07::LinearizedStep step;
    step.velocity = Eigen::Vector3d(1.0, 2.0, 3.0);
    step.inv_mass = Eigen::Vector3d::Constant(0.5);
    step.jacobian.resize(0, 3);
    step.phi.resize(0);
    step.dt = 0.1;
    const cl::lab07::StepSolution solution = cl::lab09::solve_stiff_schur(step, cl::SparseMatrix(3, 3));
    REQUIRE(cl::test::solved(solution));
    REQUIRE(solution.lambda.size() == 0);
    REQUIRE(cl::test::near(solution.velocity, Eigen::Vector3d(1.0, 2.0 - 0.981, 3.0), 1e-15));
  }
}

TEST_CASE("the Schur solve reports an indefinite M minus dt squared K_g from kept compression instead of NaN",
          "[lab09][pts=1]") {
  // Compression of 1e6 N kept in K_g: Δt²λ/ℓ is far above the masses, so
  // M − Δt²K_g (dual form) and the eliminated matrix (primal form: the
  // compliance adds stiffness along the springs only) are indefinite.
  for (std::uint64_t seed = 990; seed < 996; ++seed) {
    const Case c = make_case(seed);
    const Eigen::VectorXd compression = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(c.scene.springs.size()), 1e6);
    const cl::SparseMatrix stiffness =
        lab09_test::closed_form_stiffness(c.scene.particles.x, c.scene.springs, compression, c.map, false);
    CAPTURE(seed, c.kind, c.scene.text);
    const cl::lab07::StepSolution solution = cl::lab09::solve_stiff_schur(c.step, stiffness);
    CAPTURE(solution.problem);
    REQUIRE_FALSE(solution.ok);
    REQUIRE(solution.problem.find("not positive definite") != std::string::npos);
    REQUIRE(solution.velocity.allFinite());
    REQUIRE(solution.lambda.allFinite());
  }
}
