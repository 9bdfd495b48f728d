#include "step_residual.h"

#include <cmath>
#include <limits>
#include <vector>

#include "common/sparse.h"
#include "labs/lab06_projective_dynamics/simulation.h"

namespace cl::bench {

namespace {

double movable_mass(const lab06::Problem& problem) {
  double total = 0.0;
  for (int p : problem.map.particle_of) total += 1.0 / problem.inv_mass[p];
  return total;
}

// The spring's direction n = (x_i − x_j)/ℓ, and (1, 0, 0) for coincident ends
// (lab 06's local_step and Hessian take the same).
Eigen::Vector3d unit_of(const Eigen::Matrix3Xd& x, const Spring& spring) {
  const Eigen::Vector3d delta = x.col(spring.i) - x.col(spring.j);
  const double length = delta.norm();
  return length > 0.0 ? Eigen::Vector3d(delta / length) : Eigen::Vector3d::UnitX();
}

}  // namespace

double HardResidual::norm() const { return std::hypot(violation, stationarity); }

double step_residual(const lab06::Problem& problem, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y) {
  const Eigen::VectorXd gradient = lab06::newton_gradient(problem, x, y);
  double weighted = 0.0;  // ∇gᵀ M⁻¹ ∇g
  for (int u = 0; u < problem.map.unknowns(); ++u) {
    const int p = problem.map.particle_of[static_cast<std::size_t>(u)];
    weighted += problem.inv_mass[p] * gradient.segment<3>(3 * u).squaredNorm();
  }
  const double mass = movable_mass(problem);
  return mass > 0.0 ? problem.dt * problem.dt * std::sqrt(weighted / mass) : 0.0;
}

HardResidual hard_residual(const lab06::Problem& problem, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y,
                           SpdFactorization* factor) {
  const MovableMap& map = problem.map;
  const Eigen::Index unknowns = map.unknowns();
  HardResidual residual;
  const double mass = movable_mass(problem);
  if (unknowns == 0 || !(mass > 0.0)) return residual;

  // J over the springs with a movable end (a spring between two pins is the
  // same at every x: no solver can change its φ), and J d.
  std::vector<Triplet> jacobian;
  std::vector<double> jd;
  double violation = 0.0;
  for (const Spring& spring : problem.springs) {
    const int a = map.unknown_of[static_cast<std::size_t>(spring.i)];
    const int b = map.unknown_of[static_cast<std::size_t>(spring.j)];
    if (a < 0 && b < 0) continue;
    const Eigen::Vector3d n = unit_of(x, spring);
    const double phi = (x.col(spring.i) - x.col(spring.j)).norm() - spring.rest_length;
    violation += phi * phi;
    const int row = static_cast<int>(jd.size());
    double rate = 0.0;  // n·(d_i − d_j), pinned ends still
    for (int c = 0; c < 3; ++c) {
      if (a >= 0) jacobian.emplace_back(row, 3 * a + c, n[c]);
      if (b >= 0) jacobian.emplace_back(row, 3 * b + c, -n[c]);
    }
    if (a >= 0) rate += n.dot(x.col(spring.i) - y.col(spring.i));
    if (b >= 0) rate -= n.dot(x.col(spring.j) - y.col(spring.j));
    jd.push_back(rate);
  }
  const Eigen::Index rows = static_cast<Eigen::Index>(jd.size());
  residual.violation = rows > 0 ? std::sqrt(violation / static_cast<double>(rows)) : 0.0;

  Eigen::VectorXd d(3 * unknowns), inv_mass(3 * unknowns);
  for (Eigen::Index u = 0; u < unknowns; ++u) {
    const int p = map.particle_of[static_cast<std::size_t>(u)];
    d.segment<3>(3 * u) = x.col(p) - y.col(p);
    inv_mass.segment<3>(3 * u).setConstant(problem.inv_mass[p]);
  }
  Eigen::VectorXd r = d;  // d − M⁻¹Jᵀμ
  if (rows > 0) {
    const SparseMatrix j = assemble(rows, 3 * unknowns, jacobian);
    const SparseMatrix j_scaled = j * inv_mass.asDiagonal();
    SparseMatrix delassus = j_scaled * SparseMatrix(j.transpose());  // J M⁻¹ Jᵀ
    const double shift = 1e-10 * delassus.diagonal().mean();
    for (Eigen::Index e = 0; e < rows; ++e) delassus.coeffRef(e, e) += shift;
    SpdFactorization own;
    SpdFactorization& solver = factor ? *factor : own;
    if (!solver.refactor(delassus)) {
      residual.stationarity = std::numeric_limits<double>::quiet_NaN();
      return residual;
    }
    const Eigen::VectorXd mu = solver.solve(Eigen::Map<const Eigen::VectorXd>(jd.data(), rows));
    r -= inv_mass.asDiagonal() * (j.transpose() * mu);
  }
  residual.stationarity = std::sqrt(r.cwiseProduct(r).cwiseQuotient(inv_mass).sum() / mass);
  return residual;
}

}  // namespace cl::bench
