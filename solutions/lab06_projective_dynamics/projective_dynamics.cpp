// Lab 06 — reference solution.
#include "projective_dynamics.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cl::lab06 {

namespace {

void require_columns(const Eigen::Matrix3Xd& values, Eigen::Index count, const char* function, const char* name) {
  if (values.cols() != count) {
    throw std::invalid_argument(std::string(function) + ": " + name + " has " + std::to_string(values.cols()) +
                                " columns, expected " + std::to_string(count));
  }
}

double mass_of(const Problem& problem, int particle) { return 1.0 / problem.inv_mass[particle]; }

}  // namespace

Eigen::Matrix3Xd local_step(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  Eigen::Matrix3Xd d(3, static_cast<Eigen::Index>(springs.size()));
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const Spring& spring = springs[e];
    if (spring.i < 0 || spring.j < 0 || spring.i >= x.cols() || spring.j >= x.cols()) {
      throw std::invalid_argument("local_step: springs[" + std::to_string(e) + "] has an index outside [0, " +
                                  std::to_string(x.cols()) + ")");
    }
    const Eigen::Vector3d edge = x.col(spring.i) - x.col(spring.j);
    const double length = edge.norm();
    const auto column = static_cast<Eigen::Index>(e);
    if (length > 0.0) {
      d.col(column) = (spring.rest_length / length) * edge;
    } else {
      d.col(column) = Eigen::Vector3d(spring.rest_length, 0.0, 0.0);
    }
  }
  return d;
}

SparseMatrix system_matrix(const Problem& problem) {
  if (!std::isfinite(problem.dt) || !(problem.dt > 0.0)) {
    throw std::invalid_argument("system_matrix: dt must be finite and > 0 (got " + std::to_string(problem.dt) + ")");
  }
  const MovableMap& map = problem.map;
  const double inv_dt2 = 1.0 / (problem.dt * problem.dt);
  std::vector<Triplet> triplets;
  triplets.reserve(static_cast<std::size_t>(map.unknowns()) + 4 * problem.springs.size());
  for (int u = 0; u < map.unknowns(); ++u) triplets.emplace_back(u, u, mass_of(problem, map.particle_of[static_cast<std::size_t>(u)]) * inv_dt2);
  for (std::size_t e = 0; e < problem.springs.size(); ++e) {
    const Spring& spring = problem.springs[e];
    const double k = spring.stiffness;
    if (!std::isfinite(k) || !(k > 0.0)) {
      throw std::invalid_argument("system_matrix: springs[" + std::to_string(e) +
                                  "].stiffness must be finite and > 0 (got " + std::to_string(k) + ")");
    }
    const int a = map.unknown_of[static_cast<std::size_t>(spring.i)];
    const int b = map.unknown_of[static_cast<std::size_t>(spring.j)];
    if (a >= 0) triplets.emplace_back(a, a, k);
    if (b >= 0) triplets.emplace_back(b, b, k);
    if (a >= 0 && b >= 0) {
      triplets.emplace_back(a, b, -k);
      triplets.emplace_back(b, a, -k);
    }
  }
  return assemble(map.unknowns(), map.unknowns(), triplets);
}

RowsX3 right_hand_side(const Problem& problem, const Eigen::Matrix3Xd& y, const Eigen::Matrix3Xd& d) {
  require_columns(y, problem.inv_mass.size(), "right_hand_side", "y");
  require_columns(d, static_cast<Eigen::Index>(problem.springs.size()), "right_hand_side", "d");
  const MovableMap& map = problem.map;
  const double inv_dt2 = 1.0 / (problem.dt * problem.dt);
  RowsX3 b(map.unknowns(), 3);
  for (int u = 0; u < map.unknowns(); ++u) {
    const int p = map.particle_of[static_cast<std::size_t>(u)];
    b.row(u) = (mass_of(problem, p) * inv_dt2) * y.col(p).transpose();
  }
  for (std::size_t e = 0; e < problem.springs.size(); ++e) {
    const Spring& spring = problem.springs[e];
    const int a = map.unknown_of[static_cast<std::size_t>(spring.i)];
    const int c = map.unknown_of[static_cast<std::size_t>(spring.j)];
    const Eigen::Vector3d kd = spring.stiffness * d.col(static_cast<Eigen::Index>(e));
    if (a >= 0) {
      b.row(a) += kd.transpose();
      if (c < 0) b.row(a) += spring.stiffness * y.col(spring.j).transpose();
    }
    if (c >= 0) {
      b.row(c) -= kd.transpose();
      if (a < 0) b.row(c) += spring.stiffness * y.col(spring.i).transpose();
    }
  }
  return b;
}

Eigen::Matrix3Xd global_step(const Problem& problem, const SpdFactorization& factor, const Eigen::Matrix3Xd& y,
                             const Eigen::Matrix3Xd& d) {
  if (!factor.ok() || factor.size() != problem.map.unknowns()) {
    throw std::invalid_argument("global_step: the factorization is missing or not of A (" +
                                std::to_string(factor.size()) + " unknowns, the problem has " +
                                std::to_string(problem.map.unknowns()) + ")");
  }
  const RowsX3 b = right_hand_side(problem, y, d);
  Eigen::Matrix3Xd x = y;
  scatter_rows(factor.solve3(b), problem.map, x);
  return x;
}

double objective(const Problem& problem, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y) {
  require_columns(x, problem.inv_mass.size(), "objective", "x");
  require_columns(y, problem.inv_mass.size(), "objective", "y");
  double inertia = 0.0;
  for (int p : problem.map.particle_of) inertia += mass_of(problem, p) * (x.col(p) - y.col(p)).squaredNorm();
  double elastic = 0.0;
  for (const Spring& spring : problem.springs) {
    const double stretch = (x.col(spring.i) - x.col(spring.j)).norm() - spring.rest_length;
    elastic += spring.stiffness * stretch * stretch;
  }
  return inertia / (2.0 * problem.dt * problem.dt) + 0.5 * elastic;
}

}  // namespace cl::lab06
