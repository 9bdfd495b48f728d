// Graded tests for lab10.2, prolong_corrections: the coarse corrections reach
// the finer particles through the hierarchy's bilinear weights.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include "tests/support/catch.h"

#include "common/hierarchy.h"
#include "common/scene.h"
#include "hpbd.h"
#include "tests/support/checks.h"

using Eigen::Matrix3Xd;
using Eigen::Vector3d;

namespace {

// A flat 1.3 m × 0.9 m cloth from the scene generator (no jitter), pinned at its top corners.
cl::Scene wide_cloth(int nx, int ny) {
  return cl::parse_scene(R"({"cloth": {"nx": )" + std::to_string(nx) + R"(, "ny": )" + std::to_string(ny) +
                             R"(, "width": 1.3, "height": 0.9, "pin": ["top-left", "top-right"]}})",
                         "test-cloth-" + std::to_string(nx) + "x" + std::to_string(ny));
}

// Moves every particle of `coarse` by `motion` (a function of the start position).
template <typename Motion>
Matrix3Xd move_level(const Matrix3Xd& start, const cl::HierarchyLevel& coarse, Motion motion) {
  Matrix3Xd x = start;
  for (const int p : coarse.particles) x.col(p) = motion(start.col(p));
  return x;
}

bool on_level(const cl::HierarchyLevel& level, int particle) {
  for (const int p : level.particles) {
    if (p == particle) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("prolongation of a rigid translation is that translation on every fine vertex", "[lab10][pts=1]") {
  const Vector3d translation(0.31, -1.7, 0.05);
  for (const auto& [nx, ny] : {std::pair<int, int>{8, 8}, {9, 7}, {16, 11}, {33, 32}}) {
    const cl::Scene scene = wide_cloth(nx, ny);
    const int levels = std::min(4, cl::max_levels(nx, ny));
    const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
        nx, ny, scene.particles.x, scene.particles.inv_mass, scene.springs, levels);
    for (int l = 0; l + 1 < levels; ++l) {
      const cl::HierarchyLevel& fine = hierarchy.levels[static_cast<std::size_t>(l)];
      const cl::HierarchyLevel& coarse = hierarchy.levels[static_cast<std::size_t>(l + 1)];
      const Matrix3Xd& start = scene.particles.x;
      Matrix3Xd x = move_level(start, coarse, [&](const Vector3d& p) -> Vector3d { return p + translation; });
      cl::lab10::prolong_corrections(x, start, fine.prolongation, fine.inv_mass);
      for (const int p : fine.particles) {
        CAPTURE(nx, ny, l, p, start.col(p), translation);
        REQUIRE(cl::test::near(Vector3d(x.col(p) - start.col(p)), translation, 1e-14, "particle " + std::to_string(p)));
      }
    }
  }
}

TEST_CASE("prolongation reproduces a rotation of the flat grid and moves no pinned or other particle",
          "[lab10][pts=1]") {
  // Bilinear weights reproduce every affine map of the flat rest grid, a rotation included.
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Vector3d centre(0.2, 0.4, -0.1);
  for (const auto& [nx, ny] : {std::pair<int, int>{9, 9}, {12, 7}, {17, 20}}) {
    cl::Scene scene = wide_cloth(nx, ny);
    scene.particles.inv_mass[nx + 1] = 0.0;  // row 1, column 1: on no coarse level, pinned
    const int levels = std::min(3, cl::max_levels(nx, ny));
    const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
        nx, ny, scene.particles.x, scene.particles.inv_mass, scene.springs, levels);
    for (int l = 0; l + 1 < levels; ++l) {
      const cl::HierarchyLevel& fine = hierarchy.levels[static_cast<std::size_t>(l)];
      const cl::HierarchyLevel& coarse = hierarchy.levels[static_cast<std::size_t>(l + 1)];
      const Matrix3Xd& start = scene.particles.x;
      auto rotate = [&](const Vector3d& p) -> Vector3d { return centre + rotation * (p - centre); };
      const Matrix3Xd moved = move_level(start, coarse, rotate);
      Matrix3Xd x = moved;
      cl::lab10::prolong_corrections(x, start, fine.prolongation, fine.inv_mass);
      for (int p = 0; p < nx * ny; ++p) {
        CAPTURE(nx, ny, l, start.col(p), moved.col(p));
        Vector3d expected = moved.col(p);  // particles on the coarse level, or not on this level at all
        if (on_level(fine, p) && !on_level(coarse, p)) {
          expected = fine.inv_mass[p] > 0.0 ? rotate(start.col(p)) : Vector3d(start.col(p));
        }
        REQUIRE(cl::test::near(Vector3d(x.col(p)), expected, 1e-14, "particle " + std::to_string(p)));
      }
    }
  }
}

TEST_CASE("prolongation adds the interpolated coarse corrections to the fine particles and does not interpolate positions",
          "[lab10][pts=2]") {
  // A shaken start (no fine particle where its parents' bilinear weights put
  // it) and a random, non-affine correction of every coarse particle. Adding
  // Σ w (x_parent − start_parent) keeps each fine particle's own offset from
  // the grid; interpolating the parents' positions, Σ w x_parent, would erase
  // it — the two agree only when start is an affine image of the flat grid,
  // as in the two cases above.
  std::mt19937_64 rng(1020);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const auto& [nx, ny] : {std::pair<int, int>{9, 9}, {12, 7}, {17, 20}}) {
    const cl::Scene scene = wide_cloth(nx, ny);
    const int levels = std::min(3, cl::max_levels(nx, ny));
    const cl::ClothHierarchy hierarchy = cl::build_cloth_hierarchy(
        nx, ny, scene.particles.x, scene.particles.inv_mass, scene.springs, levels);
    Matrix3Xd start = scene.particles.x;
    for (Eigen::Index p = 0; p < start.cols(); ++p) start.col(p) += 0.05 * Vector3d(unit(rng), unit(rng), unit(rng));
    for (int l = 0; l + 1 < levels; ++l) {
      const cl::HierarchyLevel& fine = hierarchy.levels[static_cast<std::size_t>(l)];
      const cl::HierarchyLevel& coarse = hierarchy.levels[static_cast<std::size_t>(l + 1)];
      Matrix3Xd x = move_level(start, coarse, [&](const Vector3d& p) -> Vector3d {
        return p + 0.2 * Vector3d(unit(rng), unit(rng), unit(rng));
      });
      Matrix3Xd expected = x;
      double positions_miss = 0.0;  // how far interpolated positions would be off: the case must tell them apart
      for (const cl::Interpolation& e : fine.prolongation) {
        if (!(fine.inv_mass[e.particle] > 0.0)) continue;
        Vector3d correction = Vector3d::Zero(), interpolated = Vector3d::Zero();
        for (std::size_t k = 0; k < e.parents.size(); ++k) {
          correction += e.weights[k] * (x.col(e.parents[k]) - start.col(e.parents[k]));
          interpolated += e.weights[k] * x.col(e.parents[k]);
        }
        expected.col(e.particle) += correction;
        positions_miss = std::max(positions_miss, (interpolated - expected.col(e.particle)).norm());
      }
      REQUIRE(positions_miss > 1e-3);
      cl::lab10::prolong_corrections(x, start, fine.prolongation, fine.inv_mass);
      CAPTURE(nx, ny, l);
      REQUIRE(cl::test::near(x, expected, 1e-14, "particle"));
    }
  }
}
