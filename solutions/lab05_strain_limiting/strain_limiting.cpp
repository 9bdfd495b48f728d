// Lab 05 — reference solution.
#include "strain_limiting.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace cl::lab05 {

namespace {

void require_inverse_mass(double inv_mass, const char* name) {
  if (!(inv_mass >= 0.0) || !std::isfinite(inv_mass)) {
    throw std::invalid_argument(std::string(name) + " must be finite and >= 0 (got " + std::to_string(inv_mass) + ")");
  }
}

void require_band(double sigma_min, double sigma_max) {
  if (!(sigma_min > 0.0) || !std::isfinite(sigma_min) || !std::isfinite(sigma_max) || sigma_min > sigma_max) {
    throw std::invalid_argument("need 0 < sigma_min <= sigma_max, both finite (got sigma_min = " +
                                std::to_string(sigma_min) + ", sigma_max = " + std::to_string(sigma_max) + ")");
  }
}

void require_rest_area(double rest_area) {
  if (!(rest_area > 0.0) || !std::isfinite(rest_area)) {
    throw std::invalid_argument("rest area must be finite and > 0 (got " + std::to_string(rest_area) + ")");
  }
}

// ω_a = Π_{b≠a} w_b: the mass-weighted centroid's weights times w_i w_j w_k.
Eigen::Vector3d centroid_weights(const Eigen::Vector3d& inv_mass) {
  for (int a = 0; a < 3; ++a) require_inverse_mass(inv_mass[a], "inv_mass[a]");
  return Eigen::Vector3d(inv_mass[1] * inv_mass[2], inv_mass[0] * inv_mass[2], inv_mass[0] * inv_mass[1]);
}

}  // namespace

lab01::DistanceCorrection limit_spring(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j, double inv_mass_i,
                                       double inv_mass_j, double rest_length, double sigma_min, double sigma_max) {
  require_inverse_mass(inv_mass_i, "inv_mass_i");
  require_inverse_mass(inv_mass_j, "inv_mass_j");
  if (!(rest_length > 0.0) || !std::isfinite(rest_length)) {
    throw std::invalid_argument("rest_length must be finite and > 0 (got " + std::to_string(rest_length) + ")");
  }
  require_band(sigma_min, sigma_max);
  const double length = (x_i - x_j).norm();
  const double sigma = length / rest_length;
  const double clamped = std::clamp(sigma, sigma_min, sigma_max);
  // Inside the band, and the coincident case that lab 01 already makes a no-op.
  if (clamped == sigma || length == 0.0) return {};
  return lab01::project_distance(x_i, x_j, inv_mass_i, inv_mass_j, clamped * rest_length);
}

Eigen::Matrix3d limit_triangle_area(const Eigen::Matrix3d& corners, const Eigen::Vector3d& inv_mass,
                                    double rest_area, double sigma_min, double sigma_max) {
  const Eigen::Vector3d weights = centroid_weights(inv_mass);
  require_rest_area(rest_area);
  require_band(sigma_min, sigma_max);
  const Eigen::Matrix3d none = Eigen::Matrix3d::Zero();
  const double weight_sum = weights.sum();
  Eigen::Matrix<double, 3, 2> basis;
  if (weight_sum == 0.0 || !triangle_frame(corners, basis)) return none;

  const double area = 0.5 * (corners.col(1) - corners.col(0)).cross(corners.col(2) - corners.col(0)).norm();
  const double ratio = area / rest_area;
  const double clamped = std::clamp(ratio, sigma_min * sigma_min, sigma_max * sigma_max);
  if (clamped == ratio) return none;
  const double scale = std::sqrt(clamped / ratio);
  const Eigen::Vector3d centroid = corners * weights / weight_sum;
  return (scale - 1.0) * (corners.colwise() - centroid);
}

Eigen::Matrix3d limit_triangle_stretch(const Eigen::Matrix3d& corners, const Eigen::Vector3d& inv_mass,
                                       const TriangleRest& rest, double sigma_min, double sigma_max) {
  const Eigen::Vector3d weights = centroid_weights(inv_mass);
  require_rest_area(rest.area);
  // Both are used: D_m⁻¹ to form F, D_m for the rest corners.
  if (!rest.shape.allFinite()) throw std::invalid_argument("rest.shape (D_m) must be finite");
  if (!rest.inverse_shape.allFinite()) throw std::invalid_argument("rest.inverse_shape (D_m⁻¹) must be finite");
  require_band(sigma_min, sigma_max);
  const Eigen::Matrix3d none = Eigen::Matrix3d::Zero();
  const double weight_sum = weights.sum();
  Eigen::Matrix<double, 3, 2> basis;
  if (weight_sum == 0.0 || !triangle_frame(corners, basis)) return none;

  Eigen::Matrix<double, 3, 2> edges;
  edges.col(0) = corners.col(1) - corners.col(0);
  edges.col(1) = corners.col(2) - corners.col(0);
  const Eigen::Matrix2d deformed_shape = basis.transpose() * edges;
  const Eigen::Matrix2d deformation = deformed_shape * rest.inverse_shape;
  const Eigen::JacobiSVD<Eigen::Matrix2d> svd(deformation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector2d stretches = svd.singularValues();
  const Eigen::Vector2d clamped = stretches.cwiseMax(sigma_min).cwiseMin(sigma_max);
  if (clamped == stretches) return none;
  const Eigen::Matrix2d limited = svd.matrixU() * clamped.asDiagonal() * svd.matrixV().transpose();

  Eigen::Matrix<double, 2, 3> rest_corners;
  rest_corners << Eigen::Vector2d::Zero(), rest.shape;
  const Eigen::Vector3d centroid = corners * weights / weight_sum;
  const Eigen::Vector2d rest_centroid = rest_corners * weights / weight_sum;
  const Eigen::Matrix<double, 3, 2> map = basis * limited;
  const Eigen::Matrix3d rebuilt = (map * (rest_corners.colwise() - rest_centroid)).colwise() + centroid;
  return rebuilt - corners;
}

}  // namespace cl::lab05
