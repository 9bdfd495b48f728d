#include "common/metrics.h"

#include <algorithm>
#include <cmath>

namespace cl {

double strain_error(const Eigen::Matrix3Xd& x, const Spring& spring) {
  const double length = (x.col(spring.i) - x.col(spring.j)).norm();
  if (spring.rest_length == 0.0) return length;
  return std::abs(length - spring.rest_length) / spring.rest_length;
}

StrainStats strain_stats(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  StrainStats stats;
  if (springs.empty()) return stats;
  double sum_of_squares = 0.0;
  for (const Spring& spring : springs) {
    const double error = strain_error(x, spring);
    // std::max would drop a NaN; keep it visible so callers can report it.
    if (!(error <= stats.max)) stats.max = error;
    sum_of_squares += error * error;
  }
  stats.rms = std::sqrt(sum_of_squares / static_cast<double>(springs.size()));
  return stats;
}

double kinetic_energy(const Particles& particles) {
  double energy = 0.0;
  for (Eigen::Index p = 0; p < particles.size(); ++p) {
    if (particles.inv_mass[p] > 0.0) energy += 0.5 * particles.v.col(p).squaredNorm() / particles.inv_mass[p];
  }
  return energy;
}

double potential_energy(const Particles& particles, const Eigen::Vector3d& gravity) {
  double energy = 0.0;
  for (Eigen::Index p = 0; p < particles.size(); ++p) {
    if (particles.inv_mass[p] > 0.0) energy -= gravity.dot(particles.x.col(p)) / particles.inv_mass[p];
  }
  return energy;
}

Eigen::Vector3d linear_momentum(const Particles& particles) {
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
  for (Eigen::Index p = 0; p < particles.size(); ++p) {
    if (particles.inv_mass[p] > 0.0) momentum += particles.v.col(p) / particles.inv_mass[p];
  }
  return momentum;
}

bool all_finite(const Eigen::Matrix3Xd& values) { return values.allFinite(); }

}  // namespace cl
