// Hidden graded test for lab09.1 (run only by the Gradescope bundle, shown to
// the student after grades are published): how K_g scales with the forces and
// with the size of the scene.
#include <cmath>
#include <random>

#include "tests/support/catch.h"

#include "geometric_stiffness.h"
#include "lab09_scenes.h"
#include "tests/support/checks.h"

using cl::lab09::Compression;

TEST_CASE("K_g is linear in lambda and scales as one over the size of the scene", "[lab09][pts=1][hidden]") {
  // B_e = λ_e (I − n nᵀ)/ℓ: doubling every λ doubles K_g, and scaling every
  // position by s (n unchanged, ℓ → sℓ) divides K_g by s. Both to round-off.
  for (std::uint64_t seed = 1900; seed < 1906; ++seed) {
    std::mt19937_64 rng(seed);
    auto stiffness = [](int) { return 100.0; };
    const int n = 4 + static_cast<int>(seed % 4);
    const lab09_test::RandomScene scene = lab09_test::random_scene(rng, n, static_cast<int>(seed % 2), n / 2, stiffness);
    std::uniform_real_distribution<double> force(-50.0, -1.0);
    Eigen::VectorXd lambda(static_cast<Eigen::Index>(scene.springs.size()));
    for (Eigen::Index e = 0; e < lambda.size(); ++e) lambda[e] = force(rng);
    const cl::MovableMap map = cl::make_movable_map(scene.particles.inv_mass);
    const double s = 3.5;
    CAPTURE(seed, scene.text, lambda.transpose(), s);
    const Eigen::MatrixXd base(cl::lab09::geometric_stiffness(scene.particles.x, scene.springs, lambda, map,
                                                              Compression::kKeep));
    const Eigen::MatrixXd doubled(cl::lab09::geometric_stiffness(scene.particles.x, scene.springs, 2.0 * lambda,
                                                                 map, Compression::kKeep));
    const Eigen::MatrixXd scaled(cl::lab09::geometric_stiffness(s * scene.particles.x, scene.springs, lambda, map,
                                                                Compression::kKeep));
    const double scale = base.cwiseAbs().maxCoeff();
    REQUIRE(scale > 0.0);
    REQUIRE(cl::test::near(doubled, Eigen::MatrixXd(2.0 * base), 1e-13 * scale));
    REQUIRE(cl::test::near(scaled, Eigen::MatrixXd(base / s), 1e-13 * scale));
  }
}
