// Lab 02 — reference solution.
#include "gauss_seidel.h"

#include <stdexcept>
#include <string>

#include "single_spring.h"

namespace cl::lab02 {

void gauss_seidel_sweep(Eigen::Matrix3Xd& x, const Eigen::VectorXd& inv_mass,
                        const std::vector<Spring>& springs, const std::vector<int>& order) {
  if (inv_mass.size() != x.cols()) {
    throw std::invalid_argument("gauss_seidel_sweep: " + std::to_string(inv_mass.size()) + " inverse masses for " +
                                std::to_string(x.cols()) + " particles");
  }
  const int spring_count = static_cast<int>(springs.size());
  for (const int s : order) {
    if (s < 0 || s >= spring_count) {
      throw std::invalid_argument("gauss_seidel_sweep: spring index " + std::to_string(s) + " not in [0, " +
                                  std::to_string(spring_count) + ")");
    }
    const Spring& spring = springs[static_cast<std::size_t>(s)];
    const lab01::DistanceCorrection correction = lab01::project_distance(
        x.col(spring.i), x.col(spring.j), inv_mass[spring.i], inv_mass[spring.j], spring.rest_length);
    x.col(spring.i) += correction.dx_i;
    x.col(spring.j) += correction.dx_j;
  }
}

}  // namespace cl::lab02
