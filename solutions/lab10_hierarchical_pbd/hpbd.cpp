// Lab 10 — reference solution.
#include "hpbd.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "gauss_seidel.h"

namespace cl::lab10 {

lab01::DistanceCorrection project_unilateral_distance(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j,
                                                      double inv_mass_i, double inv_mass_j, double rest_length) {
  // lab01 checks the arguments and handles pinned ends; a compressed or exact
  // constraint is inactive, so it must give no correction at all.
  const lab01::DistanceCorrection projected = lab01::project_distance(x_i, x_j, inv_mass_i, inv_mass_j, rest_length);
  if ((x_i - x_j).norm() <= rest_length) return lab01::DistanceCorrection{};
  return projected;
}

void prolong_corrections(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& start,
                         const std::vector<Interpolation>& prolongation, const Eigen::VectorXd& inv_mass) {
  const Eigen::Index n = x.cols();
  if (start.cols() != n || inv_mass.size() != n) {
    throw std::invalid_argument("prolong_corrections: x has " + std::to_string(n) + " columns, start " +
                                std::to_string(start.cols()) + ", inv_mass " + std::to_string(inv_mass.size()) +
                                " entries");
  }
  auto check = [n](int index, std::size_t entry) {
    if (index < 0 || index >= n) {
      throw std::invalid_argument("prolong_corrections: entry " + std::to_string(entry) + " names particle " +
                                  std::to_string(index) + ", not in [0, " + std::to_string(n) + ")");
    }
  };
  for (std::size_t e = 0; e < prolongation.size(); ++e) {
    const Interpolation& entry = prolongation[e];
    check(entry.particle, e);
    if (entry.parents.size() != entry.weights.size()) {
      throw std::invalid_argument("prolong_corrections: entry " + std::to_string(e) + " has " +
                                  std::to_string(entry.parents.size()) + " parents and " +
                                  std::to_string(entry.weights.size()) + " weights");
    }
    for (const int parent : entry.parents) check(parent, e);
  }
  // Fine-only particles are never parents, so the order of the entries does not matter.
  for (const Interpolation& entry : prolongation) {
    if (!(inv_mass[entry.particle] > 0.0)) continue;
    Eigen::Vector3d correction = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < entry.parents.size(); ++k) {
      correction += entry.weights[k] * (x.col(entry.parents[k]) - start.col(entry.parents[k]));
    }
    x.col(entry.particle) += correction;
  }
}

void solve_hierarchy(Eigen::Matrix3Xd& x, const ClothHierarchy& hierarchy, const std::vector<int>& iterations) {
  const int levels = hierarchy.level_count();
  if (levels == 0) throw std::invalid_argument("solve_hierarchy: the hierarchy has no levels");
  if (static_cast<int>(iterations.size()) != levels) {
    throw std::invalid_argument("solve_hierarchy: " + std::to_string(iterations.size()) + " iteration counts for " +
                                std::to_string(levels) + " levels");
  }
  for (int l = 0; l < levels; ++l) {
    const int count = iterations[static_cast<std::size_t>(l)];
    if (count < 0) {
      throw std::invalid_argument("solve_hierarchy: iterations[" + std::to_string(l) + "] must be >= 0 (got " +
                                  std::to_string(count) + ")");
    }
    if (hierarchy.levels[static_cast<std::size_t>(l)].inv_mass.size() != x.cols()) {
      throw std::invalid_argument("solve_hierarchy: level " + std::to_string(l) + " has " +
                                  std::to_string(hierarchy.levels[static_cast<std::size_t>(l)].inv_mass.size()) +
                                  " inverse masses for " + std::to_string(x.cols()) + " particles");
    }
  }

  const Eigen::Matrix3Xd start = x;
  for (int l = levels - 1; l >= 1; --l) {
    const HierarchyLevel& level = hierarchy.levels[static_cast<std::size_t>(l)];
    for (int k = 0; k < iterations[static_cast<std::size_t>(l)]; ++k) {
      for (const Spring& spring : level.springs) {
        const lab01::DistanceCorrection correction =
            project_unilateral_distance(x.col(spring.i), x.col(spring.j), level.inv_mass[spring.i],
                                        level.inv_mass[spring.j], spring.rest_length);
        x.col(spring.i) += correction.dx_i;
        x.col(spring.j) += correction.dx_j;
      }
    }
    const HierarchyLevel& finer = hierarchy.levels[static_cast<std::size_t>(l - 1)];
    prolong_corrections(x, start, finer.prolongation, finer.inv_mass);
  }

  const HierarchyLevel& cloth = hierarchy.levels.front();
  std::vector<int> order(cloth.springs.size());
  for (std::size_t s = 0; s < order.size(); ++s) order[s] = static_cast<int>(s);
  for (int k = 0; k < iterations.front(); ++k) {
    lab02::gauss_seidel_sweep(x, cloth.inv_mass, cloth.springs, order);
  }
}

}  // namespace cl::lab10
