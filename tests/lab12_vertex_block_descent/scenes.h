#pragma once
// Scenes the lab 12 tests share: random particle sets, random springs, grids.
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"

namespace lab12_test {

// n particles in [-1, 1]³ with velocities in [-1, 1]³ and masses 10^U(-1, 1) kg.
inline cl::Particles random_particles(std::mt19937_64& rng, Eigen::Index n) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  cl::Particles particles;
  particles.x.resize(3, n);
  particles.v.resize(3, n);
  particles.inv_mass.resize(n);
  for (Eigen::Index p = 0; p < n; ++p) {
    particles.x.col(p) = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    particles.v.col(p) = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    particles.inv_mass[p] = std::pow(10.0, unit(rng));
  }
  return particles;
}

// A path through all particles plus `extra` random pairs; rest length = the
// current length × U(stretch_low, stretch_high), stiffness 10^U(log_k_low, log_k_high) N/m.
inline std::vector<cl::Spring> random_springs(std::mt19937_64& rng, const Eigen::Matrix3Xd& x, int extra,
                                              double stretch_low, double stretch_high, double log_k_low,
                                              double log_k_high) {
  const int n = static_cast<int>(x.cols());
  std::uniform_real_distribution<double> stretch(stretch_low, stretch_high);
  std::uniform_real_distribution<double> log_k(log_k_low, log_k_high);
  std::uniform_int_distribution<int> any(0, n - 1);
  std::vector<std::pair<int, int>> pairs;
  for (int p = 0; p + 1 < n; ++p) pairs.emplace_back(p, p + 1);
  while (extra > 0) {
    const int i = any(rng), j = any(rng);
    if (i == j) continue;
    pairs.emplace_back(i, j);
    --extra;
  }
  std::vector<cl::Spring> springs;
  for (const auto& [i, j] : pairs) {
    springs.push_back({i, j, stretch(rng) * (x.col(i) - x.col(j)).norm(), std::pow(10.0, log_k(rng))});
  }
  return springs;
}

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

inline Eigen::Matrix3Xd grid_positions(int nx, int ny, double h) {
  Eigen::Matrix3Xd x(3, nx * ny);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) x.col(j * nx + i) = Eigen::Vector3d(i * h, -j * h, 0.0);
  }
  return x;
}

}  // namespace lab12_test
