#pragma once
// Scenes the lab 12 tests share: lab 06's random particle sets and springs, and grids.
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"
#include "../lab06_projective_dynamics/test_scenes.h"

namespace lab12_test {

// Lab 06's random particle sets and springs (the same generators, so a scene
// drawn here is one lab 06's tests could draw).
using lab06_test::random_particles;
using lab06_test::random_springs;

// An nx × ny grid of particles (row-major, spacing h, in the x-y plane) with
// structural springs and, when shear is set, both diagonals of every cell.
inline std::vector<cl::Spring> grid_springs(int nx, int ny, double h, double k, bool shear) {
  std::vector<cl::Spring> springs;
  auto at = [nx](int i, int j) { return j * nx + i; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      if (i + 1 < nx) springs.push_back({at(i, j), at(i + 1, j), h, k});
      if (j + 1 < ny) springs.push_back({at(i, j), at(i, j + 1), h, k});
      if (shear && i + 1 < nx && j + 1 < ny) {
        springs.push_back({at(i, j), at(i + 1, j + 1), h * std::sqrt(2.0), k});
        springs.push_back({at(i + 1, j), at(i, j + 1), h * std::sqrt(2.0), k});
      }
    }
  }
  return springs;
}

// The three particles (gravity 0, Δt = 0.1 s, at rest): 0 and 2 of
// 1 kg, the light 1 of 1 g between them; spring 0–1 (k = 10 N/m, L = 1 m) at
// 1.1 m, stretched, and spring 1–2 (k = 1 N/m, L = 10 m) at 1 m, compressed
// and at a right angle to it. Vertex 1's full Newton step throws it 4.6 m
// across the stiff spring (its block sees that spring's curvature where it
// is, 1.1 m long), which ends 4.7 m long: g goes from 40.55 J to 79.78 J in
// the first sweep without a line search (README.md, "The line search").
struct ThreeParticles {
  cl::Particles particles;
  std::vector<cl::Spring> springs;
  double dt = 0.1;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
};

inline ThreeParticles three_particles() {
  ThreeParticles scene;
  scene.particles.x.resize(3, 3);
  scene.particles.x << 0.0, 1.1, 1.1,  //
      0.0, 0.0, -1.0,                  //
      0.0, 0.0, 0.0;
  scene.particles.v = Eigen::Matrix3Xd::Zero(3, 3);
  scene.particles.inv_mass = Eigen::Vector3d(1.0, 1000.0, 1.0);
  scene.springs = {{0, 1, 1.0, 10.0}, {1, 2, 10.0, 1.0}};
  return scene;
}

inline Eigen::Matrix3Xd grid_positions(int nx, int ny, double h) {
  Eigen::Matrix3Xd x(3, nx * ny);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) x.col(j * nx + i) = Eigen::Vector3d(i * h, -j * h, 0.0);
  }
  return x;
}

}  // namespace lab12_test
