// Lab 06 — given code: a scene's fixed data, validated once.
#include <cmath>
#include <stdexcept>
#include <string>

#include "projective_dynamics.h"

namespace cl::lab06 {

Problem make_problem(const Eigen::VectorXd& inv_mass, std::vector<Spring> springs, double dt) {
  if (!std::isfinite(dt) || !(dt > 0.0)) {
    throw std::invalid_argument("make_problem: dt must be finite and > 0 (got " + std::to_string(dt) + ")");
  }
  const Eigen::Index n = inv_mass.size();
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const Spring& spring = springs[e];
    const std::string name = "springs[" + std::to_string(e) + "]";
    if (spring.i < 0 || spring.j < 0 || spring.i >= n || spring.j >= n || spring.i == spring.j) {
      throw std::invalid_argument("make_problem: " + name + " joins " + std::to_string(spring.i) + " and " +
                                  std::to_string(spring.j) + " (needs two different particles in [0, " +
                                  std::to_string(n) + "))");
    }
    if (!std::isfinite(spring.rest_length) || spring.rest_length < 0.0) {
      throw std::invalid_argument("make_problem: " + name + ".rest must be finite and >= 0");
    }
    if (std::isinf(spring.stiffness)) {
      throw std::invalid_argument("make_problem: " + name +
                                  ".stiffness is inf (a hard constraint): projective dynamics needs finite "
                                  "springs; lab 07 handles hard constraints");
    }
    if (!std::isfinite(spring.stiffness) || !(spring.stiffness > 0.0)) {
      throw std::invalid_argument("make_problem: " + name + ".stiffness must be finite and > 0 (got " +
                                  std::to_string(spring.stiffness) + ")");
    }
  }
  Problem problem;
  problem.map = make_movable_map(inv_mass);  // throws for a negative or non-finite inverse mass
  problem.inv_mass = inv_mass;
  problem.springs = std::move(springs);
  problem.dt = dt;
  return problem;
}

}  // namespace cl::lab06
