#pragma once
// Random scenes for lab 07's graded tests. Every generated value comes from the
// seeded generator passed in, so a failing case is reproduced by its CAPTUREd seed.
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "common/constraints.h"
#include "common/particles.h"
#include "constrained.h"

namespace lab07_test {

struct RandomScene {
  cl::Particles particles;
  std::vector<cl::Spring> springs;
  std::string text;  // a readable dump for CAPTURE
};

// n particles in [-1, 1]³ (the first `pinned` of them pinned), inverse masses
// 10^U(−1, 1), velocities in [-1, 1]³. Springs: a random spanning tree whose
// links are hard (a tree of distance constraints has independent rows, so the
// Schur matrix is positive definite even at C = 0), plus `extra` springs of
// stiffness 10^U(−3, 8) N/m when soft_extras (the compliance makes any extra
// row harmless). Rest lengths are the current length times U(0.8, 1.2).
// Particles are kept at least 0.2 m apart along every spring (a tree link moves
// its new particle; an extra spring between closer particles is skipped).
inline RandomScene random_scene(std::mt19937_64& rng, int n, int pinned, int extra, bool hard_tree = true) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> scale(0.8, 1.2);
  RandomScene scene;
  cl::Particles& p = scene.particles;
  p.x.resize(3, n);
  p.v.resize(3, n);
  p.inv_mass.resize(n);
  for (int k = 0; k < n; ++k) {
    p.x.col(k) = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    p.v.col(k) = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    p.inv_mass[k] = k < pinned ? 0.0 : std::pow(10.0, unit(rng));
    if (k < pinned) p.v.col(k).setZero();
  }
  auto add = [&](int i, int j, double stiffness) {
    const double length = (p.x.col(i) - p.x.col(j)).norm();
    if (length < 0.2) p.x.col(j) = p.x.col(i) + (0.2 + 0.5 * (unit(rng) + 1.0)) * Eigen::Vector3d(1, 0, 0);
    cl::Spring s;
    s.i = i;
    s.j = j;
    s.rest_length = (p.x.col(i) - p.x.col(j)).norm() * scale(rng);
    s.stiffness = stiffness;
    scene.springs.push_back(s);
  };
  for (int k = 1; k < n; ++k) {
    std::uniform_int_distribution<int> parent(0, k - 1);
    add(parent(rng), k, hard_tree ? cl::kInfiniteStiffness : std::pow(10.0, 5.5 * unit(rng) + 2.5));
  }
  std::uniform_int_distribution<int> any(0, n - 1);
  for (int e = 0; e < extra; ++e) {
    int i = any(rng), j = any(rng);
    while (j == i) j = any(rng);
    const double stiffness = std::pow(10.0, 5.5 * unit(rng) + 2.5);
    if ((p.x.col(i) - p.x.col(j)).norm() >= 0.2) add(i, j, stiffness);
  }
  // Both ends pinned is possible only between two pinned particles; such a
  // spring cannot move and would make a hard row empty: make it soft.
  for (cl::Spring& s : scene.springs) {
    if (p.inv_mass[s.i] == 0.0 && p.inv_mass[s.j] == 0.0) s.stiffness = 1e3;
  }
  std::ostringstream text;
  text.precision(17);
  text << "x =\n" << p.x << "\nv =\n" << p.v << "\ninv_mass = " << p.inv_mass.transpose() << "\nsprings (i j rest k):";
  for (const cl::Spring& s : scene.springs) text << " (" << s.i << " " << s.j << " " << s.rest_length << " " << s.stiffness << ")";
  scene.text = text.str();
  return scene;
}

// The largest |a − b| entry of two equally sized vectors, and where it is.
struct Difference {
  double value = 0.0;
  Eigen::Index index = -1;
};
inline Difference largest_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  Difference d;
  for (Eigen::Index k = 0; k < a.size(); ++k) {
    const double diff = std::abs(a[k] - b[k]);
    if (!(diff <= d.value)) {
      d.value = diff;
      d.index = k;
    }
  }
  return d;
}

// Lab 07's KKT system written out densely from its blocks (constrained.h),
//   [ M     −ΔtJᵀ ] [ v_new ]   [ M(v + Δtg) ]
//   [ ΔtJ    C    ] [ λ     ] = [ −φ         ]
// independently of the student's kkt_system, so that the solves' tests charge
// a kkt_system mistake to lab07.2 alone.
struct DenseKkt {
  Eigen::MatrixXd matrix;
  Eigen::VectorXd rhs;
};
inline DenseKkt dense_kkt(const cl::lab07::LinearizedStep& step) {
  const Eigen::Index n3 = step.velocity.size(), m = step.phi.size();
  const Eigen::MatrixXd jacobian(step.jacobian);
  DenseKkt kkt;
  kkt.matrix = Eigen::MatrixXd::Zero(n3 + m, n3 + m);
  kkt.matrix.topLeftCorner(n3, n3) = step.inv_mass.cwiseInverse().asDiagonal();
  kkt.matrix.topRightCorner(n3, m) = -step.dt * jacobian.transpose();
  kkt.matrix.bottomLeftCorner(m, n3) = step.dt * jacobian;
  if (step.compliance.size() == m) kkt.matrix.bottomRightCorner(m, m) = step.compliance.asDiagonal();
  kkt.rhs.resize(n3 + m);
  for (Eigen::Index k = 0; k < n3; ++k) kkt.rhs[k] = (step.velocity[k] + step.dt * step.gravity[k % 3]) / step.inv_mass[k];
  kkt.rhs.tail(m) = -step.phi;
  return kkt;
}

// The same system as a KktSystem, to hand to solve_kkt.
inline cl::lab07::KktSystem sparse_kkt(const cl::lab07::LinearizedStep& step) {
  const DenseKkt kkt = dense_kkt(step);
  return cl::lab07::KktSystem{kkt.matrix.sparseView(), kkt.rhs};
}

// v_new and λ by a full-pivoting dense LU of that system: the expected values
// of both solves (the scenes here have a unique solution).
inline cl::lab07::StepSolution dense_kkt_solve(const cl::lab07::LinearizedStep& step) {
  const DenseKkt kkt = dense_kkt(step);
  const Eigen::VectorXd unknowns = kkt.matrix.fullPivLu().solve(kkt.rhs);
  cl::lab07::StepSolution solution;
  solution.velocity = unknowns.head(step.velocity.size());
  solution.lambda = unknowns.tail(step.phi.size());
  solution.ok = unknowns.allFinite();
  return solution;
}

}  // namespace lab07_test
