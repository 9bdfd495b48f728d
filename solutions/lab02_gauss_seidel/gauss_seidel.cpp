// Lab 02 — reference solution.
//
// Where the time goes: a sweep is one short projection per spring, so
// anything done per projection besides the formula shows. The arrays are
// checked once, before the sweep (what lab 01's project_distance would reject
// is rejected here, with the index), and the projection is lab 01's formula
// inline in this file, where the compiler sees the whole loop: the same
// operations in the same order as project_distance, hence the same bits.
#include "gauss_seidel.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "single_spring.h"

namespace cl::lab02 {

namespace {

// Lab 01's project_distance without its argument checks (done once per sweep).
inline lab01::DistanceCorrection project(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j, double inv_mass_i,
                                         double inv_mass_j, double rest_length) {
  lab01::DistanceCorrection correction;
  const double inv_mass_sum = inv_mass_i + inv_mass_j;
  const Eigen::Vector3d d = x_i - x_j;
  const double length = d.norm();
  if (inv_mass_sum == 0.0 || length == 0.0) return correction;
  const Eigen::Vector3d c_times_n = ((length - rest_length) / length) * d;
  correction.dx_i = -(inv_mass_i / inv_mass_sum) * c_times_n;
  correction.dx_j = (inv_mass_j / inv_mass_sum) * c_times_n;
  return correction;
}

[[noreturn]] void refuse(const std::string& what) { throw std::invalid_argument("gauss_seidel_sweep: " + what); }

}  // namespace

void gauss_seidel_sweep(Eigen::Matrix3Xd& x, const Eigen::VectorXd& inv_mass,
                        const std::vector<Spring>& springs, const std::vector<int>& order) {
  if (inv_mass.size() != x.cols()) {
    refuse(std::to_string(inv_mass.size()) + " inverse masses for " + std::to_string(x.cols()) + " particles");
  }
  // Once per sweep, on the arrays: nothing the loop reads can make it throw.
  for (Eigen::Index p = 0; p < inv_mass.size(); ++p) {
    if (!(inv_mass[p] >= 0.0) || !std::isfinite(inv_mass[p])) {
      refuse("inv_mass[" + std::to_string(p) + "] must be finite and >= 0 (got " + std::to_string(inv_mass[p]) + ")");
    }
  }
  const int spring_count = static_cast<int>(springs.size());
  for (const int s : order) {
    if (s < 0 || s >= spring_count) {
      refuse("spring index " + std::to_string(s) + " not in [0, " + std::to_string(spring_count) + ")");
    }
    const Spring& spring = springs[static_cast<std::size_t>(s)];
    if (spring.i < 0 || spring.i >= x.cols() || spring.j < 0 || spring.j >= x.cols()) {
      refuse("springs[" + std::to_string(s) + "] has a particle index outside [0, " + std::to_string(x.cols()) + ")");
    }
    if (!(spring.rest_length >= 0.0) || !std::isfinite(spring.rest_length)) {
      refuse("springs[" + std::to_string(s) + "].rest_length must be finite and >= 0 (got " +
             std::to_string(spring.rest_length) + ")");
    }
  }
  const double* w = inv_mass.data();
  for (const int s : order) {
    const Spring& spring = springs[static_cast<std::size_t>(s)];
    const lab01::DistanceCorrection correction =
        project(x.col(spring.i), x.col(spring.j), w[spring.i], w[spring.j], spring.rest_length);
    x.col(spring.i) += correction.dx_i;
    x.col(spring.j) += correction.dx_j;
  }
}

}  // namespace cl::lab02
