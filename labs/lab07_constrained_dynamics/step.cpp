// Lab 07 — given code: one constrained step from the student's pieces, and the
// post-step projection.
#include "step.h"

#include <algorithm>
#include <cmath>
#include <new>
#include <stdexcept>
#include <string>

namespace cl::lab07 {

namespace {

void check_settings(const StepSettings& settings) {
  if (!std::isfinite(settings.dt) || !(settings.dt > 0.0)) {
    throw std::invalid_argument("constrained_step: dt must be finite and > 0 (got " + std::to_string(settings.dt) +
                                ")");
  }
  if (!settings.gravity.allFinite()) throw std::invalid_argument("constrained_step: gravity must be finite");
}

void check_state(const Particles& particles, const MovableMap& map) {
  const Eigen::Index n = particles.size();
  if (particles.v.cols() != n || particles.inv_mass.size() != n) {
    throw std::invalid_argument("constrained_step: x, v and inv_mass disagree in size");
  }
  if (static_cast<Eigen::Index>(map.unknown_of.size()) != n) {
    throw std::invalid_argument("constrained_step: the movable map is for " + std::to_string(map.unknown_of.size()) +
                                " particles, the state has " + std::to_string(n));
  }
}

}  // namespace

Eigen::VectorXd compliance_of(const std::vector<Spring>& springs, double regularization) {
  if (!std::isfinite(regularization) || regularization < 0.0) {
    throw std::invalid_argument("compliance_of: regularization must be finite and >= 0 (got " +
                                std::to_string(regularization) + ")");
  }
  bool any_soft = regularization > 0.0;
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const double k = springs[e].stiffness;
    if (!(k > 0.0)) {
      throw std::invalid_argument("compliance_of: springs[" + std::to_string(e) + "].stiffness must be > 0 (got " +
                                  std::to_string(k) + ")");
    }
    if (std::isfinite(k)) any_soft = true;
  }
  if (!any_soft) return {};
  Eigen::VectorXd compliance(static_cast<Eigen::Index>(springs.size()));
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const double k = springs[e].stiffness;
    compliance[static_cast<Eigen::Index>(e)] = std::isfinite(k) ? 1.0 / k : regularization;
  }
  return compliance;
}

LinearizedStep linearize(const Particles& particles, const std::vector<Spring>& springs, const MovableMap& map,
                         const StepSettings& settings) {
  check_settings(settings);
  check_state(particles, map);
  LinearizedStep step;
  step.phi = constraint_values(particles.x, springs);
  step.jacobian = constraint_jacobian(particles.x, springs, map);
  step.compliance = compliance_of(springs, settings.regularization);
  step.velocity = gather_stacked(particles.v, map);
  step.inv_mass.resize(3 * map.unknowns());
  for (int u = 0; u < map.unknowns(); ++u) {
    step.inv_mass.segment<3>(3 * u).setConstant(particles.inv_mass[map.particle_of[static_cast<std::size_t>(u)]]);
  }
  step.gravity = settings.gravity;
  step.dt = settings.dt;
  return step;
}

std::string solution_problem(const StepSolution& solution, Eigen::Index unknowns, Eigen::Index constraints) {
  if (!solution.ok) return solution.problem.empty() ? "the solve failed without saying why" : solution.problem;
  if (solution.velocity.size() != unknowns || solution.lambda.size() != constraints) {
    return "the solve returned v_new or lambda of the wrong size";
  }
  if (!solution.velocity.allFinite() || !solution.lambda.allFinite()) {
    return "the solve returned a non-finite v_new or lambda";
  }
  return {};
}

StepResult constrained_step(Particles& particles, const std::vector<Spring>& springs, const StepSettings& settings) {
  check_settings(settings);
  return constrained_step(particles, springs, make_movable_map(particles.inv_mass), settings);
}

std::string out_of_memory_problem(Method method, Eigen::Index unknowns, Eigen::Index constraints) {
  const std::string sizes = std::to_string(unknowns) + " velocity unknowns, " + std::to_string(constraints) +
                            " constraints";
  if (method == Method::kKkt) {
    const std::string side = std::to_string(unknowns + constraints);
    return "out of memory in the KKT solve: its matrix is " + side + " x " + side + " (" + sizes +
           ") and its factorization fills in far beyond that; try a smaller scene, or --method schur (a " +
           std::to_string(constraints) + " x " + std::to_string(constraints) + " system)";
  }
  return "out of memory in the Schur solve: its matrix dt^2 J W J^T + C is " + std::to_string(constraints) + " x " +
         std::to_string(constraints) + " (" + sizes + "); try a smaller scene (fewer springs)";
}

StepResult constrained_step(Particles& particles, const std::vector<Spring>& springs, const MovableMap& map,
                            const StepSettings& settings) {
  StepSolution solution;
  Eigen::Index unknowns = 0;
  try {
    const LinearizedStep step = linearize(particles, springs, map, settings);
    unknowns = step.velocity.size();
    if (settings.method == Method::kKkt) {
      solution = solve_kkt(kkt_system(step), unknowns);
    } else {
      solution = solve_schur(step);
    }
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(out_of_memory_problem(settings.method, 3 * static_cast<Eigen::Index>(map.unknowns()),
                                                   static_cast<Eigen::Index>(springs.size())));
  }
  StepResult result;
  result.problem = solution_problem(solution, unknowns, static_cast<Eigen::Index>(springs.size()));
  if (!result.problem.empty()) return result;
  result.ok = true;
  update_positions(particles, map, solution.velocity, settings.dt);
  result.lambda = std::move(solution.lambda);
  return result;
}

double max_constraint_error(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  if (springs.empty()) return 0.0;
  return constraint_values(x, springs).cwiseAbs().maxCoeff();
}

namespace {

std::vector<Spring> hard_springs(const std::vector<Spring>& springs) {
  std::vector<Spring> hard;
  for (const Spring& spring : springs) {
    if (!std::isfinite(spring.stiffness)) hard.push_back(spring);
  }
  return hard;
}

Eigen::VectorXd stacked_inv_mass(const Particles& particles, const MovableMap& map) {
  Eigen::VectorXd inv_mass(3 * map.unknowns());
  for (int u = 0; u < map.unknowns(); ++u) {
    inv_mass.segment<3>(3 * u).setConstant(particles.inv_mass[map.particle_of[static_cast<std::size_t>(u)]]);
  }
  return inv_mass;
}

}  // namespace

bool hard_constraints_redundant(const Particles& particles, const std::vector<Spring>& springs,
                                const MovableMap& map) {
  check_state(particles, map);
  const std::vector<Spring> hard = hard_springs(springs);
  if (hard.empty()) return false;
  const SparseMatrix jacobian = constraint_jacobian(particles.x, hard, map);
  const SparseMatrix weighted = stacked_inv_mass(particles, map).asDiagonal() * SparseMatrix(jacobian.transpose());
  SpdFactorization factor;
  return !factor.factor(jacobian * weighted);
}

ProjectionResult stabilize_positions(Particles& particles, const std::vector<Spring>& springs,
                                     const MovableMap& map) {
  check_state(particles, map);
  ProjectionResult result;
  const std::vector<Spring> hard = hard_springs(springs);
  result.hard_constraints = static_cast<int>(hard.size());
  if (hard.empty()) return result;

  const Eigen::VectorXd phi = constraint_values(particles.x, hard);
  result.max_error_before = phi.cwiseAbs().maxCoeff();
  result.max_error_after = result.max_error_before;
  const SparseMatrix jacobian = constraint_jacobian(particles.x, hard, map);
  const SparseMatrix weighted = stacked_inv_mass(particles, map).asDiagonal() * SparseMatrix(jacobian.transpose());
  const SparseMatrix normal = jacobian * weighted;
  SpdFactorization factor;
  if (!factor.factor(normal)) {
    result.ok = false;
    result.problem = "stabilize: J W J^T of the hard constraints is singular (redundant hard constraints)";
    return result;
  }
  const Eigen::VectorXd mu = factor.solve(-phi);
  const Eigen::VectorXd dx = weighted * mu;
  if (!dx.allFinite()) {
    result.ok = false;
    result.problem = "stabilize: the projection is not finite";
    return result;
  }
  for (int u = 0; u < map.unknowns(); ++u) {
    particles.x.col(map.particle_of[static_cast<std::size_t>(u)]) += dx.segment<3>(3 * u);
  }
  result.max_error_after = constraint_values(particles.x, hard).cwiseAbs().maxCoeff();
  return result;
}

}  // namespace cl::lab07
