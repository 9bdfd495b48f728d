// Graded test for lab09.3, eliminated_system: with K_g built from the springs'
// own forces (λ = −kφ) and C = 1/k, eliminating λ gives implicit Euler's
// system for the same springs, matrix M + Δt²H and right-hand side
// M(v + Δt g) + Δt f(x). H is taken from central differences of the spring
// force, written out here independently of lab 07 and lab 09, and K_g from
// its closed form (lab09_scenes.h), not from the student's geometric_stiffness:
// a K_g mistake is charged to lab09.1 alone.
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "tests/support/catch.h"

#include "constrained.h"
#include "geometric_stiffness.h"
#include "lab09_scenes.h"
#include "step.h"
#include "tests/support/checks.h"

using cl::lab09::Compression;

namespace {

// f(x) = −Σ_e k_e φ_e ∂φ_e/∂x over the movable unknowns, stacked: particle i
// gets −k φ n, particle j gets +k φ n, with n = (x_i − x_j)/‖x_i − x_j‖.
Eigen::VectorXd spring_force(const Eigen::Matrix3Xd& x, const std::vector<cl::Spring>& springs,
                             const cl::MovableMap& map) {
  Eigen::VectorXd force = Eigen::VectorXd::Zero(3 * map.unknowns());
  for (const cl::Spring& s : springs) {
    const Eigen::Vector3d d = x.col(s.i) - x.col(s.j);
    const double length = d.norm();
    const Eigen::Vector3d pull = s.stiffness * (length - s.rest_length) * d / length;
    const int ui = map.unknown_of[static_cast<std::size_t>(s.i)];
    const int uj = map.unknown_of[static_cast<std::size_t>(s.j)];
    if (ui >= 0) force.segment<3>(3 * ui) -= pull;
    if (uj >= 0) force.segment<3>(3 * uj) += pull;
  }
  return force;
}

}  // namespace

TEST_CASE("with K_g from the spring forces and C equal to 1 over k the eliminated system is implicit Euler's",
          "[lab09][pts=3]") {
  // Stiffness 1 … 1e3 N/m, rest lengths 0.7 … 1.3 times the current length
  // (springs stretched and compressed, Compression::kKeep) or 0.7 … 0.95
  // (all stretched, where kDrop drops nothing). H = −∂f/∂x by central
  // differences with h = 1e-6: error about 1e-12·k/ℓ³ + 1e-16·|f|/h, far
  // below the 1e-6 relative tolerance on M + Δt²H.
  const double h = 1e-6;
  for (std::uint64_t seed = 940; seed < 948; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> exponent(0.0, 3.0);
    auto stiffness = [&](int) { return std::pow(10.0, exponent(rng)); };
    const bool all_stretched = seed % 2 == 1;
    const int n = 3 + static_cast<int>(seed % 4);
    const int pinned = static_cast<int>(seed % 3 == 0);
    const lab09_test::RandomScene scene =
        lab09_test::random_scene(rng, n, pinned, n / 2, stiffness, 0.7, all_stretched ? 0.95 : 1.3);
    const Compression compression = all_stretched ? Compression::kDrop : Compression::kKeep;
    cl::lab07::StepSettings settings;
    settings.dt = seed % 4 == 0 ? 0.1 : 1.0 / 60.0;
    settings.gravity = Eigen::Vector3d(0.2, -9.81, 0.4);
    const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
    const cl::lab07::LinearizedStep step = cl::lab07::linearize(scene.particles, scene.springs, map, settings);
    const Eigen::VectorXd lambda = -step.phi.cwiseQuotient(step.compliance);  // the springs' forces, −kφ
    CAPTURE(seed, n, pinned, all_stretched, settings.dt, scene.text, lambda.transpose());

    const cl::SparseMatrix stiffness_matrix = lab09_test::closed_form_stiffness(
        scene.particles.x, scene.springs, lambda, map, compression == Compression::kDrop);
    const cl::lab09::EliminatedSystem system = cl::lab09::eliminated_system(step, stiffness_matrix);

    const Eigen::Index size = 3 * map.unknowns();
    Eigen::MatrixXd hessian(size, size);
    for (int u = 0; u < map.unknowns(); ++u) {
      for (int c = 0; c < 3; ++c) {
        Eigen::Matrix3Xd plus = scene.particles.x, minus = scene.particles.x;
        plus(c, map.particle_of[static_cast<std::size_t>(u)]) += h;
        minus(c, map.particle_of[static_cast<std::size_t>(u)]) -= h;
        hessian.col(3 * u + c) =
            -(spring_force(plus, scene.springs, map) - spring_force(minus, scene.springs, map)) / (2.0 * h);
      }
    }
    const Eigen::VectorXd mass = step.inv_mass.cwiseInverse();
    const double dt = settings.dt;
    const Eigen::MatrixXd implicit_euler = Eigen::MatrixXd(mass.asDiagonal()) + dt * dt * hessian;
    const Eigen::MatrixXd actual(system.matrix);
    const double matrix_scale = implicit_euler.cwiseAbs().maxCoeff();
    CAPTURE(matrix_scale);
    REQUIRE(cl::test::near(actual, implicit_euler, 1e-6 * matrix_scale));

    const Eigen::VectorXd gravity = settings.gravity.replicate(map.unknowns(), 1);
    const Eigen::VectorXd rhs = mass.cwiseProduct(step.velocity + dt * gravity) +
                                dt * spring_force(scene.particles.x, scene.springs, map);
    const double rhs_scale = std::max(1.0, rhs.cwiseAbs().maxCoeff());
    CAPTURE(rhs_scale);
    REQUIRE(cl::test::near(system.rhs, rhs, 1e-12 * rhs_scale));
  }

  SECTION("a hard constraint cannot be eliminated: std::invalid_argument") {
    std::mt19937_64 rng(950);
    auto mixed = [](int e) { return e == 1 ? cl::kInfiniteStiffness : 100.0; };
    const lab09_test::RandomScene scene = lab09_test::random_scene(rng, 4, 1, 0, mixed);
    const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
    const cl::lab07::LinearizedStep step =
        cl::lab07::linearize(scene.particles, scene.springs, map, cl::lab07::StepSettings{});
    const cl::SparseMatrix zero(3 * map.unknowns(), 3 * map.unknowns());
    CAPTURE(scene.text, step.compliance.transpose());
    REQUIRE_THROWS_AS(cl::lab09::eliminated_system(step, zero), std::invalid_argument);
    cl::lab07::LinearizedStep all_hard = step;
    all_hard.compliance.resize(0);
    REQUIRE_THROWS_AS(cl::lab09::eliminated_system(all_hard, zero), std::invalid_argument);
  }
}
