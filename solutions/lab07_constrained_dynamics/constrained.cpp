// Lab 07 — reference solution.
#include "constrained.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/SparseLU>

namespace cl::lab07 {

namespace {

void check_springs(const char* function, Eigen::Index particle_count, const std::vector<Spring>& springs) {
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const Spring& s = springs[e];
    const bool in_range = s.i >= 0 && s.j >= 0 && s.i < particle_count && s.j < particle_count;
    if (in_range && s.i != s.j && std::isfinite(s.rest_length) && s.rest_length >= 0.0) continue;
    // The message is built only for the spring that fails: these checks run
    // on every call, once per spring, inside lab 13's line search.
    const std::string where = std::string(function) + ": springs[" + std::to_string(e) + "]";
    if (!in_range) {
      throw std::invalid_argument(where + " has an index out of range (" + std::to_string(s.i) + ", " +
                                  std::to_string(s.j) + ") for " + std::to_string(particle_count) + " particles");
    }
    if (s.i == s.j) throw std::invalid_argument(where + " joins particle " + std::to_string(s.i) + " to itself");
    if (!std::isfinite(s.rest_length) || s.rest_length < 0.0) {
      throw std::invalid_argument(where + ".rest_length must be finite and >= 0 (got " +
                                  std::to_string(s.rest_length) + ")");
    }
  }
}

void check_step(const char* function, const LinearizedStep& step) {
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

// max over rows of Σ_j |a_ij|, the infinity norm.
double row_sum_norm(const SparseMatrix& a) {
  Eigen::VectorXd sums = Eigen::VectorXd::Zero(a.rows());
  for (int k = 0; k < a.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(a, k); it; ++it) sums[it.row()] += std::abs(it.value());
  }
  return a.rows() > 0 ? sums.maxCoeff() : 0.0;
}

// The KKT matrix with its constraint rows negated, S = diag(I, −I) A, when S is
// symmetric quasi-definite: S = [H, Bᵀ; B, −G] with H positive definite (a
// positive diagonal that strictly dominates its rows: Gershgorin) and G
// diagonal with every entry > 0 (every c_e > 0). Such an S has an LDLᵀ in any
// symmetric ordering, no pivoting (README.md, Vanderbei 1995). Returns false,
// leaving `symmetric` unspecified, otherwise (a hard constraint, c_e = 0).
bool quasi_definite_form(const SparseMatrix& a, Eigen::Index velocity_unknowns, SparseMatrix& symmetric) {
  const Eigen::Index n = velocity_unknowns;
  const Eigen::Index size = a.rows();
  symmetric = a;
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(size);
  Eigen::VectorXd off_diagonal = Eigen::VectorXd::Zero(size);  // Σ |H_rc|, c ≠ r, rows of H only
  for (int c = 0; c < symmetric.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(symmetric, c); it; ++it) {
      if (it.row() >= n) it.valueRef() = -it.value();
      const bool lower_right = it.row() >= n && it.col() >= n;
      if (it.row() == it.col()) {
        diagonal[it.row()] = it.value();
      } else if (lower_right) {
        return false;  // G is not diagonal
      } else if (it.row() < n && it.col() < n) {
        off_diagonal[it.row()] += std::abs(it.value());
      }
    }
  }
  for (Eigen::Index k = 0; k < size; ++k) {
    if (k < n ? !(diagonal[k] > off_diagonal[k]) : !(diagonal[k] < 0.0)) return false;
  }
  // Symmetric exactly: kkt_system writes ΔtJ and −ΔtJᵀ from the same values.
  const SparseMatrix difference = symmetric - SparseMatrix(symmetric.transpose());
  for (Eigen::Index k = 0; k < difference.nonZeros(); ++k) {
    if (difference.valuePtr()[k] != 0.0) return false;
  }
  return true;
}

// True when z solves A z = b to the tolerance of the contract (a pivot that is
// zero only up to round-off gives a finite z that misses the system).
bool solves(const SparseMatrix& a, const Eigen::VectorXd& z, const Eigen::VectorXd& b, double& residual) {
  residual = a.rows() > 0 ? (a * z - b).cwiseAbs().maxCoeff() : 0.0;
  return a.rows() == 0 ||
         residual <= 1e-8 * (row_sum_norm(a) * z.cwiseAbs().maxCoeff() + b.cwiseAbs().maxCoeff());
}

// g repeated for every unknown.
Eigen::VectorXd stacked_gravity(const LinearizedStep& step) {
  return step.gravity.replicate(step.velocity.size() / 3, 1);
}

}  // namespace

Eigen::VectorXd constraint_values(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  check_springs("constraint_values", x.cols(), springs);
  Eigen::VectorXd phi(static_cast<Eigen::Index>(springs.size()));
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const Spring& s = springs[e];
    phi[static_cast<Eigen::Index>(e)] = (x.col(s.i) - x.col(s.j)).norm() - s.rest_length;
  }
  return phi;
}

SparseMatrix constraint_jacobian(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs,
                                 const MovableMap& map) {
  check_springs("constraint_jacobian", x.cols(), springs);
  if (static_cast<Eigen::Index>(map.unknown_of.size()) != x.cols()) {
    throw std::invalid_argument("constraint_jacobian: the map is for " + std::to_string(map.unknown_of.size()) +
                                " particles, x has " + std::to_string(x.cols()));
  }
  // Row e holds spring e's (at most six) entries, so the rows are written in
  // order into a row-major matrix (no triplets to sort) and converted once.
  // A direction that is not finite (an infinite coordinate) goes through
  // assemble() instead, whose error names the entry.
  const auto rows = static_cast<Eigen::Index>(springs.size());
  Eigen::SparseMatrix<double, Eigen::RowMajor> by_row(rows, 3 * map.unknowns());
  by_row.reserve(Eigen::VectorXi::Constant(rows, 6));
  bool finite = true;
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const Spring& s = springs[e];
    const Eigen::Vector3d d = x.col(s.i) - x.col(s.j);
    const double length = d.norm();
    if (!(length > 0.0)) continue;  // coincident: no direction, empty row
    const Eigen::Vector3d n = d / length;
    finite = finite && n.allFinite();
    const auto row = static_cast<Eigen::Index>(e);
    const int ui = map.unknown_of[static_cast<std::size_t>(s.i)];
    const int uj = map.unknown_of[static_cast<std::size_t>(s.j)];
    for (int c = 0; c < 3; ++c) {
      if (ui >= 0) by_row.insert(row, 3 * ui + c) = n[c];
      if (uj >= 0) by_row.insert(row, 3 * uj + c) = -n[c];
    }
  }
  by_row.makeCompressed();
  if (finite) return SparseMatrix(by_row);
  std::vector<Triplet> triplets;
  for (Eigen::Index e = 0; e < rows; ++e) {
    for (decltype(by_row)::InnerIterator it(by_row, e); it; ++it) {
      triplets.emplace_back(static_cast<int>(e), static_cast<int>(it.col()), it.value());
    }
  }
  return assemble(rows, 3 * map.unknowns(), triplets);
}

KktSystem kkt_system(const LinearizedStep& step) {
  check_step("kkt_system", step);
  const Eigen::Index n3 = step.velocity.size();
  const Eigen::Index m = step.phi.size();
  const double dt = step.dt;
  std::vector<Triplet> triplets;
  triplets.reserve(static_cast<std::size_t>(n3 + 2 * step.jacobian.nonZeros() + step.compliance.size()));
  for (Eigen::Index k = 0; k < n3; ++k) triplets.emplace_back(k, k, 1.0 / step.inv_mass[k]);
  for (int e = 0; e < step.jacobian.outerSize(); ++e) {
    for (SparseMatrix::InnerIterator it(step.jacobian, e); it; ++it) {
      triplets.emplace_back(it.col(), n3 + it.row(), -dt * it.value());  // −ΔtJᵀ
      triplets.emplace_back(n3 + it.row(), it.col(), dt * it.value());   // +ΔtJ
    }
  }
  for (Eigen::Index e = 0; e < step.compliance.size(); ++e) {
    if (step.compliance[e] != 0.0) triplets.emplace_back(n3 + e, n3 + e, step.compliance[e]);
  }
  KktSystem system;
  system.matrix = assemble(n3 + m, n3 + m, triplets);
  system.rhs.resize(n3 + m);
  const Eigen::VectorXd predicted = step.velocity + dt * stacked_gravity(step);
  system.rhs.head(n3) = predicted.cwiseQuotient(step.inv_mass);  // M(v + Δt g)
  system.rhs.tail(m) = -step.phi;
  return system;
}

StepSolution solve_kkt(const KktSystem& system, Eigen::Index velocity_unknowns) {
  const Eigen::Index size = system.matrix.rows();
  if (system.matrix.cols() != size || system.rhs.size() != size) {
    throw std::invalid_argument("solve_kkt: the matrix is " + std::to_string(size) + " x " +
                                std::to_string(system.matrix.cols()) + ", the right-hand side has " +
                                std::to_string(system.rhs.size()) + " entries");
  }
  if (velocity_unknowns < 0 || velocity_unknowns > size) {
    throw std::invalid_argument("solve_kkt: velocity_unknowns " + std::to_string(velocity_unknowns) +
                                " is outside [0, " + std::to_string(size) + "]");
  }
  StepSolution solution;
  auto accept = [&](const Eigen::VectorXd& unknowns) {
    solution.velocity = unknowns.head(velocity_unknowns);
    solution.lambda = unknowns.tail(size - velocity_unknowns);
    solution.ok = true;
    return solution;
  };
  double residual = 0.0;
  // Every c_e > 0: the LDLᵀ of the symmetric quasi-definite form S in the
  // order "multipliers first". Their pivots are −c_e and they fill nothing
  // among themselves; what is left for the velocities is
  //     R = H + (ΔtJ)ᵀ C⁻¹ (ΔtJ)   (H = M, or lab 09's M − Δt²K_g),
  // symmetric positive definite, factored by SpdFactorization (CHOLMOD's
  // supernodal LLᵀ when it is large). Should it refuse, or round-off defeat
  // the answer, the LU below decides.
  SparseMatrix symmetric;
  if (size > velocity_unknowns && quasi_definite_form(system.matrix, velocity_unknowns, symmetric)) {
    const Eigen::Index n = velocity_unknowns;
    const Eigen::Index m = size - n;
    const SparseMatrix upper_left = system.matrix.topLeftCorner(n, n);
    const SparseMatrix lower_left = system.matrix.bottomLeftCorner(m, n);  // ΔtJ; the upper right is −(ΔtJ)ᵀ
    const Eigen::VectorXd inverse_compliance = system.matrix.diagonal().tail(m).cwiseInverse();
    const SparseMatrix lower_left_transpose = lower_left.transpose();
    const SparseMatrix reduced =
        upper_left + lower_left_transpose * (inverse_compliance.asDiagonal() * lower_left);
    SpdFactorization factor;
    if (factor.factor(reduced)) {
      const Eigen::VectorXd scaled = inverse_compliance.cwiseProduct(system.rhs.tail(m));  // C⁻¹ b₂
      Eigen::VectorXd unknowns(size);
      unknowns.head(n) = factor.solve(system.rhs.head(n) + lower_left_transpose * scaled);
      unknowns.tail(m) = scaled - inverse_compliance.cwiseProduct(lower_left * unknowns.head(n));
      if (unknowns.allFinite() && solves(system.matrix, unknowns, system.rhs, residual)) return accept(unknowns);
    }
  }
  // Some c_e = 0 (the lower-right block is singular): LU with partial pivoting,
  // correct for any non-singular matrix.
  Eigen::SparseLU<SparseMatrix, Eigen::COLAMDOrdering<int>> lu;
  lu.analyzePattern(system.matrix);
  lu.factorize(system.matrix);
  if (lu.info() != Eigen::Success) {
    solution.problem = "the KKT matrix is singular (LU failed: " + lu.lastErrorMessage() + ")";
    return solution;
  }
  const Eigen::VectorXd unknowns = lu.solve(system.rhs);
  if (lu.info() != Eigen::Success || !unknowns.allFinite()) {
    solution.problem = "the KKT matrix is singular (the LU solve is not finite)";
    return solution;
  }
  if (!solves(system.matrix, unknowns, system.rhs, residual)) {
    solution.problem = "the KKT matrix is singular (the LU solution misses the system by " +
                       std::to_string(residual) + ")";
    return solution;
  }
  return accept(unknowns);
}

StepSolution solve_schur(const LinearizedStep& step) {
  check_step("solve_schur", step);
  const Eigen::Index m = step.phi.size();
  const double dt = step.dt;
  const Eigen::VectorXd predicted = step.velocity + dt * stacked_gravity(step);  // v + Δt g
  StepSolution solution;
  if (m == 0) {
    solution.velocity = predicted;
    solution.lambda.resize(0);
    solution.ok = true;
    return solution;
  }
  const SparseMatrix weighted = step.inv_mass.asDiagonal() * SparseMatrix(step.jacobian.transpose());  // W Jᵀ
  SparseMatrix schur = (dt * dt) * (step.jacobian * weighted);
  if (step.compliance.size() != 0) {
    std::vector<Triplet> diagonal;
    for (Eigen::Index e = 0; e < m; ++e) {
      if (step.compliance[e] != 0.0) diagonal.emplace_back(e, e, step.compliance[e]);
    }
    schur += assemble(m, m, diagonal);
  }
  SpdFactorization factor;
  if (!factor.factor(schur)) {
    solution.problem =
        "the Schur complement dt^2 J W J^T + C is singular (redundant hard constraints, or a hard constraint "
        "that nothing can move)";
    return solution;
  }
  const Eigen::VectorXd rhs = -step.phi - dt * (step.jacobian * predicted);
  solution.lambda = factor.solve(rhs);
  solution.velocity = predicted + dt * (weighted * solution.lambda);
  if (!solution.lambda.allFinite() || !solution.velocity.allFinite()) {
    solution.velocity.resize(0);
    solution.lambda.resize(0);
    solution.problem = "the Schur solve is not finite";
    return solution;
  }
  solution.ok = true;
  return solution;
}

void update_positions(Particles& particles, const MovableMap& map, const Eigen::VectorXd& velocity, double dt) {
  const Eigen::Index n = particles.size();
  if (!std::isfinite(dt) || !(dt > 0.0)) {
    throw std::invalid_argument("update_positions: dt must be finite and > 0 (got " + std::to_string(dt) + ")");
  }
  if (particles.v.cols() != n || static_cast<Eigen::Index>(map.unknown_of.size()) != n ||
      velocity.size() != 3 * map.unknowns()) {
    throw std::invalid_argument("update_positions: " + std::to_string(n) + " particles, a map of " +
                                std::to_string(map.unknown_of.size()) + " with " + std::to_string(map.unknowns()) +
                                " unknowns, and " + std::to_string(velocity.size()) + " velocity entries disagree");
  }
  particles.v.setZero();
  scatter_stacked(velocity, map, particles.v);
  particles.x += dt * particles.v;  // pinned columns have v = 0
}

}  // namespace cl::lab07
