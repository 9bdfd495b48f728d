// Lab 03 — reference solution.
//
// The arrays are checked once, before the parallel loop, and the projection
// is lab 01's formula inline in this file (the same operations in the same
// order as project_distance, hence the same bits), so that the compiler sees
// the whole gather loop and no projection pays for a call or a check.
#include "jacobi.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "single_spring.h"

namespace cl::lab03 {

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

}  // namespace

void jacobi_sweep(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& x_next, const Eigen::VectorXd& inv_mass,
                  const std::vector<Spring>& springs, const Incidence& incidence, double omega,
                  Averaging averaging) {
  const Eigen::Index n = x.cols();
  if (inv_mass.size() != n || static_cast<Eigen::Index>(incidence.offset.size()) != n + 1 ||
      incidence.spring.size() != 2 * springs.size()) {
    throw std::invalid_argument("jacobi_sweep: shapes disagree (" + std::to_string(n) + " particles, " +
                                std::to_string(inv_mass.size()) + " inverse masses, " +
                                std::to_string(springs.size()) + " springs)");
  }
  if (!(omega >= 0.0) || !std::isfinite(omega)) {
    throw std::invalid_argument("jacobi_sweep: omega must be finite and >= 0 (got " + std::to_string(omega) + ")");
  }
  // An exception may not leave an OpenMP region, so everything project_distance
  // would reject is rejected here, before the parallel loop.
  if (!inv_mass.allFinite() || (inv_mass.array() < 0.0).any()) {
    throw std::invalid_argument("jacobi_sweep: inverse masses must be finite and >= 0");
  }
  for (const Spring& spring : springs) {
    if (!(spring.rest_length >= 0.0) || !std::isfinite(spring.rest_length)) {
      throw std::invalid_argument("jacobi_sweep: rest lengths must be finite and >= 0");
    }
    if (spring.i < 0 || spring.i >= n || spring.j < 0 || spring.j >= n) {
      throw std::invalid_argument("jacobi_sweep: a spring has a particle index outside [0, " + std::to_string(n) + ")");
    }
  }
  x_next.resize(3, n);
#pragma omp parallel for schedule(static)
  for (Eigen::Index p = 0; p < n; ++p) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const auto begin = static_cast<std::size_t>(incidence.offset[static_cast<std::size_t>(p)]);
    const auto end = static_cast<std::size_t>(incidence.offset[static_cast<std::size_t>(p) + 1]);
    for (std::size_t k = begin; k < end; ++k) {
      const Spring& spring = springs[static_cast<std::size_t>(incidence.spring[k])];
      const lab01::DistanceCorrection correction =
          project(x.col(spring.i), x.col(spring.j), inv_mass[spring.i], inv_mass[spring.j], spring.rest_length);
      sum += spring.i == p ? correction.dx_i : correction.dx_j;
    }
    const double count = averaging == Averaging::kByCount && end > begin ? static_cast<double>(end - begin) : 1.0;
    x_next.col(p) = x.col(p) + (omega / count) * sum;
  }
}

}  // namespace cl::lab03
