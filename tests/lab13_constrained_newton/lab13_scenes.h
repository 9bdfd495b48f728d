#pragma once
// Scenes and dense helpers for lab 13's graded tests. Every generated value
// comes from the seeded generator passed in, so a failing case is reproduced
// by its CAPTUREd seed.
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"
#include "common/scene.h"
#include "common/sparse.h"

namespace lab13_test {

struct RandomScene {
  cl::Particles particles;
  std::vector<cl::Spring> springs;
  std::string text;  // a readable dump for CAPTURE
};

// n particles in [-1, 1]³, the first `pinned` of them pinned, inverse masses
// 10^U(−1, 1), velocities in [-1, 1]³; a chain 0-1-…-(n−1) plus `extra` random
// pairs, every spring at least 0.3 m long, rest lengths the current length
// times U(0.8, 1.2), stiffness `k` (inf: hard).
inline RandomScene random_scene(std::mt19937_64& rng, int n, int pinned, int extra, double k) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> rest(0.8, 1.2);
  RandomScene scene;
  cl::Particles& p = scene.particles;
  p.x.resize(3, n);
  p.v.resize(3, n);
  p.inv_mass.resize(n);
  for (int i = 0; i < n; ++i) {
    p.x.col(i) = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    p.v.col(i) = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    p.inv_mass[i] = i < pinned ? 0.0 : std::pow(10.0, unit(rng));
    if (i < pinned) p.v.col(i).setZero();
  }
  auto add = [&](int i, int j) {
    Eigen::Vector3d d = p.x.col(i) - p.x.col(j);
    if (d.norm() < 0.3) {
      p.x(0, j) = p.x(0, i) - 0.3 - d.norm();
      d = p.x.col(i) - p.x.col(j);
    }
    scene.springs.push_back({i, j, d.norm() * rest(rng), k});
  };
  for (int i = 0; i + 1 < n; ++i) add(i, i + 1);
  std::uniform_int_distribution<int> pick(0, n - 1);
  for (int e = 0; e < extra; ++e) {
    const int i = pick(rng);
    int j = pick(rng);
    if (j == i) j = (i + 1) % n;
    add(i, j);
  }
  std::ostringstream text;
  text.precision(17);
  text << "x =\n" << p.x << "\nv =\n" << p.v << "\ninv_mass = " << p.inv_mass.transpose() << "\nsprings:";
  for (const cl::Spring& s : scene.springs) text << " (" << s.i << "," << s.j << ", L " << s.rest_length << ")";
  scene.text = text.str();
  return scene;
}

// A curtain of nx × nx particles (1 m × 1 m, 1 kg in all, top row pinned,
// structural and shear springs of stiffness k) in lab 06's breeze
// (gravity (0, −9.81, 3) m/s²), dt 1/60 s: the common/ cloth generator.
inline cl::Scene curtain(int nx, double k) {
  std::ostringstream text;
  text.precision(17);
  text << R"({"name": "test-curtain", "gravity": [0, -9.81, 3], "dt": 0.016666666666666666, "steps": 1,
             "cloth": {"nx": )"
       << nx << R"(, "ny": )" << nx << R"(, "width": 1, "height": 1, "mass": 1, "pin": ["top"],
             "springs": ["structural", "shear"], "stiffness": )"
       << (std::isfinite(k) ? std::to_string(k) : std::string("\"inf\"")) << "}}";
  return cl::parse_scene(text.str(), "test-curtain");
}

}  // namespace lab13_test
