// Lab 12 — reference solution (vbd.h is the contract).
#include "vbd.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#ifdef _OPENMP
#include <omp.h>
#endif

namespace cl::lab12 {

namespace {

void require_shape(const Eigen::Matrix3Xd& m, Eigen::Index n, const char* what) {
  if (m.cols() != n) {
    throw std::invalid_argument(std::string(what) + " has " + std::to_string(m.cols()) + " columns, expected " +
                                std::to_string(n));
  }
}

}  // namespace

VertexBlock vertex_block(const lab06::Problem& problem, const Adjacency& adjacency, const Eigen::Matrix3Xd& x,
                         const Eigen::Matrix3Xd& y, int vertex) {
  const Eigen::Index n = problem.inv_mass.size();
  require_shape(x, n, "vertex_block: x");
  require_shape(y, n, "vertex_block: y");
  if (vertex < 0 || vertex >= n || adjacency.offsets.size() != static_cast<std::size_t>(n) + 1) {
    throw std::invalid_argument("vertex_block: vertex " + std::to_string(vertex) + " is outside [0, " +
                                std::to_string(n) + ") or the adjacency is not for these particles");
  }
  VertexBlock block;
  const double inv_mass = problem.inv_mass[vertex];
  if (inv_mass > 0.0) {
    const double weight = 1.0 / (inv_mass * problem.dt * problem.dt);  // m_i/Δt²
    block.force = -weight * (x.col(vertex) - y.col(vertex));
    block.hessian = weight * Eigen::Matrix3d::Identity();
  }
  const auto v = static_cast<std::size_t>(vertex);
  for (int s = adjacency.offsets[v]; s < adjacency.offsets[v + 1]; ++s) {
    const Spring& spring = problem.springs[static_cast<std::size_t>(adjacency.springs[static_cast<std::size_t>(s)])];
    // lab 06's direction n of x_i − x_j ((1, 0, 0) for coincident ends); end
    // i's gradient is k (l − L) n, end j's its negative.
    const Eigen::Vector3d edge = x.col(spring.i) - x.col(spring.j);
    const double length = edge.norm();
    const Eigen::Vector3d unit = length > 0.0 ? Eigen::Vector3d(edge / length) : Eigen::Vector3d::UnitX();
    const double sign = spring.i == vertex ? 1.0 : -1.0;
    block.force -= (sign * spring.stiffness * (length - spring.rest_length)) * unit;
    double across = 1.0;
    if (spring.rest_length > 0.0 && length > 0.0) {
      across = std::max(0.0, 1.0 - spring.rest_length / length);
    } else if (spring.rest_length > 0.0) {
      across = 0.0;
    }
    const Eigen::Matrix3d along = unit * unit.transpose();
    block.hessian += spring.stiffness * (along + across * (Eigen::Matrix3d::Identity() - along));
  }
  return block;
}

Eigen::Vector3d vertex_newton_step(const VertexBlock& block, double inv_mass) {
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  if (!(inv_mass > 0.0) || !block.force.allFinite() || !block.hessian.allFinite()) return none;
  const double scale = block.hessian.cwiseAbs().maxCoeff();
  if (!(scale > 0.0)) return none;
  // The determinant of H/s (entries in [−1, 1]) against the relative threshold: no overflow.
  const Eigen::Matrix3d scaled = block.hessian / scale;
  if (!(std::abs(scaled.determinant()) > kSingularDeterminant)) return none;
  const Eigen::Vector3d step = scaled.ldlt().solve(block.force) / scale;
  return step.allFinite() ? step : none;
}

Eigen::Vector3d vertex_update(const lab06::Problem& problem, const Adjacency& adjacency, const Eigen::Matrix3Xd& x,
                              const Eigen::Matrix3Xd& y, int vertex) {
  const VertexBlock block = vertex_block(problem, adjacency, x, y, vertex);
  const Eigen::Vector3d direction = vertex_newton_step(block, problem.inv_mass[vertex]);
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  const double slope = block.force.dot(direction);  // f·d = dᵀHd > 0 for a descent direction
  if (!(slope > 0.0)) return none;
  double alpha = 1.0;
  for (int halving = 0; halving <= kMaxHalvings; ++halving, alpha *= 0.5) {
    const Eigen::Vector3d step = alpha * direction;
    if (vertex_energy_change(problem, adjacency, x, y, vertex, step) <= -kSufficientDecrease * alpha * slope) {
      return step;
    }
  }
  return none;
}

std::vector<int> colour_particles(int particles, const std::vector<Spring>& springs) {
  if (particles < 0) throw std::invalid_argument("colour_particles: a negative number of particles");
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const Spring& s = springs[e];
    if (s.i < 0 || s.j < 0 || s.i >= particles || s.j >= particles || s.i == s.j) {
      throw std::invalid_argument("colour_particles: springs[" + std::to_string(e) + "] joins " +
                                  std::to_string(s.i) + " and " + std::to_string(s.j));
    }
  }
  const Adjacency adjacency = make_adjacency(particles, springs);
  std::vector<int> colours(static_cast<std::size_t>(particles), -1);
  std::vector<int> taken;  // taken[c] == p: colour c is used by a neighbour of p
  for (int p = 0; p < particles; ++p) {
    const auto pp = static_cast<std::size_t>(p);
    for (int a = adjacency.offsets[pp]; a < adjacency.offsets[pp + 1]; ++a) {
      const Spring& s = springs[static_cast<std::size_t>(adjacency.springs[static_cast<std::size_t>(a)])];
      const int colour = colours[static_cast<std::size_t>(s.i == p ? s.j : s.i)];
      if (colour < 0) continue;
      if (static_cast<std::size_t>(colour) >= taken.size()) taken.resize(static_cast<std::size_t>(colour) + 1, -1);
      taken[static_cast<std::size_t>(colour)] = p;
    }
    int colour = 0;
    while (static_cast<std::size_t>(colour) < taken.size() && taken[static_cast<std::size_t>(colour)] == p) ++colour;
    colours[pp] = colour;
  }
  return colours;
}

void vbd_sweep(const lab06::Problem& problem, const Adjacency& adjacency, const std::vector<std::vector<int>>& groups,
               const Eigen::Matrix3Xd& y, Eigen::Matrix3Xd& x) {
  const Eigen::Index n = problem.inv_mass.size();
  require_shape(x, n, "vbd_sweep: x");
  require_shape(y, n, "vbd_sweep: y");
  const auto update = [&](int p) {
    x.col(p) += vertex_update(problem, adjacency, x, y, p);
  };
#ifdef _OPENMP
  // One team per sweep and a barrier per colour. On one thread no team at
  // all: libgomp's barrier makes a system call even for a team of one, which
  // on a small mesh cost more than the sweep (the extremes' VBD cells).
  if (omp_get_max_threads() > 1) {
#pragma omp parallel
    for (const std::vector<int>& group : groups) {
      const int size = static_cast<int>(group.size());
#pragma omp for schedule(static)
      for (int g = 0; g < size; ++g) update(group[static_cast<std::size_t>(g)]);
    }
    return;
  }
#endif
  for (const std::vector<int>& group : groups) {
    for (const int p : group) update(p);
  }
}

}  // namespace cl::lab12
