// Lab 09 — given code: the step with geometric stiffness, the heavy chain, the
// transverse speed.
#include "stable_step.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace cl::lab09 {

lab07::StepSolution solve_stiff(const lab07::LinearizedStep& step, const SparseMatrix& stiffness,
                                lab07::Method method) {
  if (method == lab07::Method::kKkt) {
    return lab07::solve_kkt(stiff_kkt_system(step, stiffness), step.velocity.size());
  }
  return solve_stiff_schur(step, stiffness);
}

StableStepResult stable_step(Particles& particles, const std::vector<Spring>& springs, const MovableMap& map,
                             const StableSettings& settings, const Eigen::VectorXd& previous_lambda) {
  const lab07::LinearizedStep step = lab07::linearize(particles, springs, map, settings.step);
  const Eigen::Index size = step.velocity.size();
  StableStepResult result;
  SparseMatrix stiffness(size, size);  // K_g = 0
  if (settings.geometric_stiffness && !springs.empty()) {
    Eigen::VectorXd lambda_bar = previous_lambda;
    if (lambda_bar.size() != static_cast<Eigen::Index>(springs.size())) {
      const lab07::StepSolution first = solve_stiff(step, stiffness, settings.step.method);
      result.problem = lab07::solution_problem(first, size, step.phi.size());
      if (!result.problem.empty()) return result;
      lambda_bar = first.lambda;
      result.first_solve = true;
    }
    stiffness = geometric_stiffness(particles.x, springs, lambda_bar, map, settings.compression);
  }
  lab07::StepSolution solution = solve_stiff(step, stiffness, settings.step.method);
  result.problem = lab07::solution_problem(solution, size, step.phi.size());
  if (!result.problem.empty()) return result;
  lab07::update_positions(particles, map, solution.velocity, settings.step.dt);
  result.ok = true;
  result.lambda = std::move(solution.lambda);
  return result;
}

double max_transverse_speed(const Particles& particles, const std::vector<Spring>& springs) {
  double fastest = 0.0;
  for (const Spring& spring : springs) {
    const Eigen::Vector3d d = particles.x.col(spring.i) - particles.x.col(spring.j);
    const double length = d.norm();
    if (!(length > 0.0)) continue;
    const Eigen::Vector3d unit = d / length;
    const Eigen::Vector3d relative = particles.v.col(spring.i) - particles.v.col(spring.j);
    const Eigen::Vector3d across = relative - unit.dot(relative) * unit;
    fastest = std::max(fastest, across.norm());
  }
  return fastest;
}

double spring_energy(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  double energy = 0.0;
  for (const Spring& spring : springs) {
    if (!std::isfinite(spring.stiffness)) continue;
    const double stretch = (x.col(spring.i) - x.col(spring.j)).norm() - spring.rest_length;
    energy += 0.5 * spring.stiffness * stretch * stretch;
  }
  return energy;
}

Scene heavy_chain(int links, double link_length, double bead_mass, double mass_ratio, double stiffness,
                  double kick) {
  if (links < 2) throw std::invalid_argument("heavy_chain: links must be >= 2 (got " + std::to_string(links) + ")");
  auto positive = [](const char* what, double value) {
    if (!(value > 0.0)) {
      throw std::invalid_argument(std::string("heavy_chain: ") + what + " must be > 0 (got " +
                                  std::to_string(value) + ")");
    }
  };
  positive("link_length", link_length);
  positive("bead_mass", bead_mass);
  positive("mass_ratio", mass_ratio);
  positive("stiffness", stiffness);
  if (!(kick >= 0.0) || !std::isfinite(kick)) {
    throw std::invalid_argument("heavy_chain: kick must be finite and >= 0 (got " + std::to_string(kick) + ")");
  }
  Scene scene;
  char name[64];
  std::snprintf(name, sizeof name, "heavy-chain-ratio-%g", mass_ratio);
  scene.name = name;
  scene.source = "heavy_chain()";
  const double g = 9.81;
  scene.gravity = Eigen::Vector3d(0.0, -g, 0.0);
  scene.dt = 1.0 / 60.0;
  const Eigen::Index n = links + 1;
  scene.particles.x.setZero(3, n);
  scene.particles.v.setZero(3, n);
  scene.particles.inv_mass.resize(n);
  scene.particles.inv_mass[0] = 0.0;
  const double heavy = mass_ratio * bead_mass;
  double y = 0.0;
  for (int p = 1; p <= links; ++p) {
    // Link p (from particle p−1 to p) carries the weight of everything below it.
    const double below = heavy + (links - p) * bead_mass;
    const double stretch = std::isfinite(stiffness) ? below * g / stiffness : 0.0;
    y -= link_length + stretch;
    scene.particles.x(1, p) = y;
    scene.particles.inv_mass[p] = p == links ? 1.0 / heavy : 1.0 / bead_mass;
    if (p < links) scene.particles.v(0, p) = (p % 2 == 1 ? kick : -kick);
    scene.springs.push_back({p - 1, p, link_length, stiffness});
  }
  return scene;
}

}  // namespace cl::lab09
