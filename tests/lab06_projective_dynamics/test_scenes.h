#pragma once
// Scenes the lab 06 tests share: random particle sets and small cloths.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/output.h"
#include "common/particles.h"
#include "common/scene.h"

namespace lab06_test {

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

// Springs between random pairs (a path through all particles plus `extra`
// random pairs), rest length = the current length × U(stretch_low, stretch_high),
// stiffness 10^U(log_k_low, log_k_high) N/m.
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

// An n × n cloth of 1 kg hanging from its two top corners with springs of
// `stiffness` N/m (structural and shear), with a 1 mm jitter.
inline cl::Scene cloth(int n, double stiffness) {
  const std::string size = std::to_string(n);
  return cl::parse_scene(R"({"cloth": {"nx": )" + size + R"(, "ny": )" + size +
                             R"(, "pin": ["top-left", "top-right"], "stiffness": )" + cl::format_double(stiffness) +
                             R"(}, "jitter": {"amplitude": 0.001, "seed": 3}})",
                         "test-cloth-" + size);
}

}  // namespace lab06_test
