// Lab 01 — reference solution.
#include "single_spring.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cl::lab01 {

namespace {
void require_inverse_mass(double inv_mass, const char* name) {
  if (!(inv_mass >= 0.0) || !std::isfinite(inv_mass)) {
    throw std::invalid_argument(std::string(name) + " must be finite and >= 0 (got " +
                                std::to_string(inv_mass) + ")");
  }
}
}  // namespace

DistanceCorrection project_distance(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j,
                                    double inv_mass_i, double inv_mass_j, double rest_length) {
  require_inverse_mass(inv_mass_i, "inv_mass_i");
  require_inverse_mass(inv_mass_j, "inv_mass_j");
  if (!(rest_length >= 0.0) || !std::isfinite(rest_length)) {
    throw std::invalid_argument("rest_length must be finite and >= 0 (got " + std::to_string(rest_length) + ")");
  }
  DistanceCorrection correction;
  const double inv_mass_sum = inv_mass_i + inv_mass_j;
  const Eigen::Vector3d d = x_i - x_j;
  const double length = d.norm();
  if (inv_mass_sum == 0.0 || length == 0.0) return correction;
  // C·n with n = d/‖d‖, folded into one scale of d.
  const Eigen::Vector3d c_times_n = ((length - rest_length) / length) * d;
  correction.dx_i = -(inv_mass_i / inv_mass_sum) * c_times_n;
  correction.dx_j = (inv_mass_j / inv_mass_sum) * c_times_n;
  return correction;
}

Eigen::Matrix3Xd project_constraint(double constraint, const Eigen::Matrix3Xd& gradients,
                                    const Eigen::VectorXd& inv_mass) {
  if (gradients.cols() != inv_mass.size()) {
    throw std::invalid_argument("project_constraint: " + std::to_string(gradients.cols()) + " gradients for " +
                                std::to_string(inv_mass.size()) + " inverse masses");
  }
  if (!std::isfinite(constraint) || !gradients.allFinite()) {
    throw std::invalid_argument("project_constraint: C and its gradients must be finite");
  }
  for (Eigen::Index k = 0; k < inv_mass.size(); ++k) require_inverse_mass(inv_mass[k], "inv_mass[k]");
  const double denominator = gradients.colwise().squaredNorm().dot(inv_mass);
  if (denominator == 0.0) return Eigen::Matrix3Xd::Zero(3, gradients.cols());
  return (-constraint / denominator) * (gradients * inv_mass.asDiagonal());
}

}  // namespace cl::lab01
