#pragma once
// Random scenes and dense helpers for lab 09's graded tests. Every generated
// value comes from the seeded generator passed in, so a failing case is
// reproduced by its CAPTUREd seed.
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"
#include "common/sparse.h"

namespace lab09_test {

struct RandomScene {
  cl::Particles particles;
  std::vector<cl::Spring> springs;
  std::string text;  // a readable dump for CAPTURE
};

// n particles in [-1, 1]³, the first `pinned` of them pinned, inverse masses
// 10^U(−1, 1), velocities in [-1, 1]³. Springs: a chain 0-1-…-(n−1) (its rows
// are independent, so hard links keep every Schur matrix definite) plus `extra`
// random pairs. Every spring is at least 0.3 m long (a closer particle is moved
// out along x). `stiffness(e)` gives spring e's stiffness (inf: hard); rest
// lengths are the current length times U(rest_low, rest_high).
template <typename Stiffness>
RandomScene random_scene(std::mt19937_64& rng, int n, int pinned, int extra, Stiffness stiffness,
                         double rest_low = 0.8, double rest_high = 1.2) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> rest(rest_low, rest_high);
  RandomScene scene;
  cl::Particles& p = scene.particles;
  p.x.resize(3, n);
  p.v.resize(3, n);
  p.inv_mass.resize(n);
  for (int k = 0; k < n; ++k) {
    p.x.col(k) = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    p.v.col(k) = k < pinned ? Eigen::Vector3d::Zero() : Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    p.inv_mass[k] = k < pinned ? 0.0 : std::pow(10.0, unit(rng));
  }
  auto add = [&](int i, int j) {
    if ((p.x.col(i) - p.x.col(j)).norm() < 0.3) {
      if (j < pinned) return;  // do not move a pinned particle: skip the spring
      p.x.col(j) = p.x.col(i) + (0.3 + 0.5 * (unit(rng) + 1.0)) * Eigen::Vector3d(1, 0, 0);
    }
    cl::Spring s;
    s.i = i;
    s.j = j;
    s.rest_length = (p.x.col(i) - p.x.col(j)).norm() * rest(rng);
    s.stiffness = stiffness(static_cast<int>(scene.springs.size()));
    scene.springs.push_back(s);
  };
  for (int k = 1; k < n; ++k) add(k - 1, k);
  std::uniform_int_distribution<int> any(0, n - 1);
  for (int e = 0; e < extra; ++e) {
    const int i = any(rng);
    int j = any(rng);
    while (j == i) j = any(rng);
    if ((p.x.col(i) - p.x.col(j)).norm() >= 0.3) add(i, j);
  }
  std::ostringstream text;
  text.precision(17);
  text << "x =\n" << p.x << "\nv =\n" << p.v << "\ninv_mass = " << p.inv_mass.transpose() << "\nsprings (i j rest k):";
  for (const cl::Spring& s : scene.springs) {
    text << " (" << s.i << " " << s.j << " " << s.rest_length << " " << s.stiffness << ")";
  }
  scene.text = text.str();
  return scene;
}

// K_g written out from its closed form (geometric_stiffness.h): for spring e
// with d = x_i − x_j, ℓ = ‖d‖, n = d/ℓ, the block B_e = λ_e (I − n nᵀ)/ℓ goes in
// at +(i, i), +(j, j), −(i, j), −(j, i) over map's unknowns; pinned ends and
// ℓ = 0 add nothing, and with `drop_compression` neither does λ_e > 0. The
// tests of lab09.2–09.4 use this, not the student's geometric_stiffness, so a
// K_g mistake is charged to lab09.1 alone.
inline cl::SparseMatrix closed_form_stiffness(const Eigen::Matrix3Xd& x, const std::vector<cl::Spring>& springs,
                                              const Eigen::VectorXd& lambda, const cl::MovableMap& map,
                                              bool drop_compression) {
  const Eigen::Index size = 3 * map.unknowns();
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(size, size);
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const double force = lambda[static_cast<Eigen::Index>(e)];
    if (drop_compression && force > 0.0) continue;
    const Eigen::Vector3d d = x.col(springs[e].i) - x.col(springs[e].j);
    const double length = d.norm();
    if (length == 0.0) continue;
    const Eigen::Vector3d n = d / length;
    const Eigen::Matrix3d block = force * (Eigen::Matrix3d::Identity() - n * n.transpose()) / length;
    const int a = map.unknown_of[static_cast<std::size_t>(springs[e].i)];
    const int b = map.unknown_of[static_cast<std::size_t>(springs[e].j)];
    if (a >= 0) dense.block<3, 3>(3 * a, 3 * a) += block;
    if (b >= 0) dense.block<3, 3>(3 * b, 3 * b) += block;
    if (a >= 0 && b >= 0) {
      dense.block<3, 3>(3 * a, 3 * b) -= block;
      dense.block<3, 3>(3 * b, 3 * a) -= block;
    }
  }
  return dense.sparseView();
}

}  // namespace lab09_test
