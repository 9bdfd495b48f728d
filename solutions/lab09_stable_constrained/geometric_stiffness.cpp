// Lab 09 — reference solution.
#include "geometric_stiffness.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cl::lab09 {

namespace {

// The checks lab 07's kkt_system makes, plus K_g's shape.
void check_step(const char* function, const lab07::LinearizedStep& step, const SparseMatrix& geometric_stiffness) {
  const Eigen::Index m = step.phi.size();
  const Eigen::Index n3 = step.velocity.size();
  if (step.jacobian.rows() != m || step.jacobian.cols() != n3 || step.inv_mass.size() != n3 || n3 % 3 != 0 ||
      (step.compliance.size() != 0 && step.compliance.size() != m)) {
    throw std::invalid_argument(std::string(function) + ": sizes disagree (phi " + std::to_string(m) +
                                ", jacobian " + std::to_string(step.jacobian.rows()) + " x " +
                                std::to_string(step.jacobian.cols()) + ", compliance " +
                                std::to_string(step.compliance.size()) + ", inv_mass " +
                                std::to_string(step.inv_mass.size()) + ", velocity " + std::to_string(n3) + ")");
  }
  if (geometric_stiffness.rows() != n3 || geometric_stiffness.cols() != n3) {
    throw std::invalid_argument(std::string(function) + ": geometric_stiffness is " +
                                std::to_string(geometric_stiffness.rows()) + " x " +
                                std::to_string(geometric_stiffness.cols()) + ", the step has " + std::to_string(n3) +
                                " velocity unknowns");
  }
  if (!std::isfinite(step.dt) || !(step.dt > 0.0)) {
    throw std::invalid_argument(std::string(function) + ": dt must be finite and > 0 (got " +
                                std::to_string(step.dt) + ")");
  }
  for (Eigen::Index k = 0; k < n3; ++k) {
    if (!std::isfinite(step.inv_mass[k]) || !(step.inv_mass[k] > 0.0)) {
      throw std::invalid_argument(std::string(function) + ": inv_mass[" + std::to_string(k) +
                                  "] must be finite and > 0 (got " + std::to_string(step.inv_mass[k]) + ")");
    }
  }
}

bool all_compliant(const lab07::LinearizedStep& step) {
  if (step.compliance.size() == 0) return false;
  return (step.compliance.array() > 0.0).all();
}

// M (v + Δt g), stacked.
Eigen::VectorXd momentum_rhs(const lab07::LinearizedStep& step) {
  const Eigen::VectorXd gravity = step.gravity.replicate(step.velocity.size() / 3, 1);
  const Eigen::VectorXd predicted = step.velocity + step.dt * gravity;
  return predicted.cwiseQuotient(step.inv_mass);
}

// M − Δt² K_g.
SparseMatrix stiff_mass(const lab07::LinearizedStep& step, const SparseMatrix& geometric_stiffness) {
  const Eigen::VectorXd mass = step.inv_mass.cwiseInverse();
  SparseMatrix matrix = -(step.dt * step.dt) * geometric_stiffness;
  std::vector<Triplet> diagonal;
  diagonal.reserve(static_cast<std::size_t>(mass.size()));
  for (Eigen::Index k = 0; k < mass.size(); ++k) diagonal.emplace_back(k, k, mass[k]);
  matrix += assemble(mass.size(), mass.size(), diagonal);
  return matrix;
}

}  // namespace

SparseMatrix geometric_stiffness(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs,
                                 const Eigen::VectorXd& lambda, const MovableMap& map,
                                 Compression compression) {
  const Eigen::Index n = x.cols();
  if (static_cast<Eigen::Index>(map.unknown_of.size()) != n) {
    throw std::invalid_argument("geometric_stiffness: the map is for " + std::to_string(map.unknown_of.size()) +
                                " particles, x has " + std::to_string(n));
  }
  if (lambda.size() != static_cast<Eigen::Index>(springs.size())) {
    throw std::invalid_argument("geometric_stiffness: lambda has " + std::to_string(lambda.size()) +
                                " entries for " + std::to_string(springs.size()) + " springs");
  }
  std::vector<Triplet> triplets;
  triplets.reserve(36 * springs.size());
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const Spring& s = springs[e];
    const std::string where = "geometric_stiffness: springs[" + std::to_string(e) + "]";
    if (s.i < 0 || s.j < 0 || s.i >= n || s.j >= n) {
      throw std::invalid_argument(where + " has an index out of range (" + std::to_string(s.i) + ", " +
                                  std::to_string(s.j) + ") for " + std::to_string(n) + " particles");
    }
    if (s.i == s.j) throw std::invalid_argument(where + " joins particle " + std::to_string(s.i) + " to itself");
    double force = lambda[static_cast<Eigen::Index>(e)];
    if (!std::isfinite(force)) {
      throw std::invalid_argument("geometric_stiffness: lambda[" + std::to_string(e) + "] is not finite");
    }
    if (compression == Compression::kDrop) force = std::min(force, 0.0);
    const Eigen::Vector3d d = x.col(s.i) - x.col(s.j);
    const double length = d.norm();
    if (force == 0.0 || !(length > 0.0)) continue;  // nothing to add, or no direction
    const Eigen::Vector3d unit = d / length;
    const Eigen::Matrix3d block = (force / length) * (Eigen::Matrix3d::Identity() - unit * unit.transpose());
    const int ui = map.unknown_of[static_cast<std::size_t>(s.i)];
    const int uj = map.unknown_of[static_cast<std::size_t>(s.j)];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        const double value = block(r, c);
        if (ui >= 0) triplets.emplace_back(3 * ui + r, 3 * ui + c, value);
        if (uj >= 0) triplets.emplace_back(3 * uj + r, 3 * uj + c, value);
        if (ui >= 0 && uj >= 0) {
          triplets.emplace_back(3 * ui + r, 3 * uj + c, -value);
          triplets.emplace_back(3 * uj + r, 3 * ui + c, -value);
        }
      }
    }
  }
  return assemble(3 * map.unknowns(), 3 * map.unknowns(), triplets);
}

lab07::KktSystem stiff_kkt_system(const lab07::LinearizedStep& step, const SparseMatrix& geometric_stiffness) {
  check_step("stiff_kkt_system", step, geometric_stiffness);
  lab07::KktSystem system = lab07::kkt_system(step);
  // −Δt² K_g embedded in the upper-left block of the (3u + m) square matrix.
  std::vector<Triplet> triplets;
  triplets.reserve(static_cast<std::size_t>(geometric_stiffness.nonZeros()));
  const double scale = -step.dt * step.dt;
  for (int col = 0; col < geometric_stiffness.outerSize(); ++col) {
    for (SparseMatrix::InnerIterator it(geometric_stiffness, col); it; ++it) {
      triplets.emplace_back(it.row(), it.col(), scale * it.value());
    }
  }
  system.matrix += assemble(system.matrix.rows(), system.matrix.cols(), triplets);
  return system;
}

EliminatedSystem eliminated_system(const lab07::LinearizedStep& step, const SparseMatrix& geometric_stiffness) {
  check_step("eliminated_system", step, geometric_stiffness);
  if (step.compliance.size() == 0 && step.phi.size() > 0) {
    throw std::invalid_argument("eliminated_system: every constraint is hard (no compliance): λ cannot be eliminated");
  }
  for (Eigen::Index e = 0; e < step.compliance.size(); ++e) {
    if (!std::isfinite(step.compliance[e]) || !(step.compliance[e] > 0.0)) {
      throw std::invalid_argument("eliminated_system: compliance[" + std::to_string(e) +
                                  "] must be finite and > 0 (got " + std::to_string(step.compliance[e]) +
                                  "): a hard constraint cannot be eliminated this way");
    }
  }
  const double dt = step.dt;
  const Eigen::VectorXd stiffness = step.compliance.cwiseInverse();  // C⁻¹ (N/m)
  const SparseMatrix weighted_jacobian = stiffness.asDiagonal() * step.jacobian;  // C⁻¹ J
  const SparseMatrix jacobian_transpose = step.jacobian.transpose();
  EliminatedSystem system;
  system.matrix = stiff_mass(step, geometric_stiffness) + (dt * dt) * (jacobian_transpose * weighted_jacobian);
  system.rhs = momentum_rhs(step) - dt * (jacobian_transpose * stiffness.cwiseProduct(step.phi));
  return system;
}

lab07::StepSolution solve_stiff_schur(const lab07::LinearizedStep& step, const SparseMatrix& geometric_stiffness) {
  check_step("solve_stiff_schur", step, geometric_stiffness);
  const Eigen::Index m = step.phi.size();
  const double dt = step.dt;
  const Eigen::VectorXd momentum = momentum_rhs(step);
  lab07::StepSolution solution;

  if (m > 0 && all_compliant(step)) {
    // Primal: one sparse SPD solve for v_new, then λ from the constraint row.
    const EliminatedSystem system = eliminated_system(step, geometric_stiffness);
    SpdFactorization factor;
    if (!factor.factor(system.matrix)) {
      solution.problem =
          "the eliminated matrix M - dt^2 K_g + dt^2 J^T C^-1 J is not positive definite (compressed "
          "constraints kept in K_g?)";
      return solution;
    }
    solution.velocity = factor.solve(system.rhs);
    solution.lambda = -(step.phi + dt * (step.jacobian * solution.velocity)).cwiseQuotient(step.compliance);
  } else {
    // Dual: M̃ = M − Δt² K_g factored once, then lab 07's Schur complement with M̃⁻¹ for W.
    SpdFactorization mass_factor;
    if (!mass_factor.factor(stiff_mass(step, geometric_stiffness))) {
      solution.problem = "M - dt^2 K_g is not positive definite (compressed constraints kept in K_g?)";
      return solution;
    }
    const Eigen::VectorXd free_velocity = mass_factor.solve(momentum);  // M̃⁻¹ M (v + Δt g)
    if (m == 0) {
      solution.velocity = free_velocity;
      solution.lambda.resize(0);
    } else {
      const Eigen::MatrixXd jacobian_transpose = Eigen::MatrixXd(step.jacobian.transpose());
      const Eigen::MatrixXd solved = mass_factor.eigen().solve(jacobian_transpose);  // M̃⁻¹ Jᵀ, 3u × m
      Eigen::MatrixXd schur = (dt * dt) * (step.jacobian * solved);
      if (step.compliance.size() != 0) schur.diagonal() += step.compliance;
      // The dense matrix goes through the same SPD check as lab 07's sparse one.
      SpdFactorization schur_factor;
      if (!schur_factor.factor(schur.sparseView())) {
        solution.problem =
            "the Schur complement dt^2 J (M - dt^2 K_g)^-1 J^T + C is singular (redundant hard constraints, or a "
            "hard constraint that nothing can move)";
        return solution;
      }
      const Eigen::VectorXd rhs = -step.phi - dt * (step.jacobian * free_velocity);
      solution.lambda = schur_factor.solve(rhs);
      solution.velocity = free_velocity + dt * (solved * solution.lambda);
    }
  }
  if (!solution.velocity.allFinite() || !solution.lambda.allFinite()) {
    solution.velocity.resize(0);
    solution.lambda.resize(0);
    solution.problem = "the Schur solve is not finite";
    return solution;
  }
  solution.ok = true;
  return solution;
}

}  // namespace cl::lab09
