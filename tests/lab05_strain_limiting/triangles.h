#pragma once
// Helpers shared by the triangle tests (not graded themselves).
#include <cmath>
#include <random>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "strain_limiting.h"

namespace lab05_test {

// The centroid weights of the header: ω = (w_j w_k, w_i w_k, w_i w_j).
inline Eigen::Vector3d centroid_weights(const Eigen::Vector3d& w) {
  return Eigen::Vector3d(w[1] * w[2], w[0] * w[2], w[0] * w[1]);
}

inline double area_of(const Eigen::Matrix3d& corners) {
  return 0.5 * (corners.col(1) - corners.col(0)).cross(corners.col(2) - corners.col(0)).norm();
}

inline Eigen::Vector3d normal_of(const Eigen::Matrix3d& corners) {
  return (corners.col(1) - corners.col(0)).cross(corners.col(2) - corners.col(0)).normalized();
}

// The interior angle at each corner, rad.
inline Eigen::Vector3d angles_of(const Eigen::Matrix3d& corners) {
  Eigen::Vector3d angles;
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3d u = corners.col((a + 1) % 3) - corners.col(a);
    const Eigen::Vector3d v = corners.col((a + 2) % 3) - corners.col(a);
    angles[a] = std::atan2(u.cross(v).norm(), u.dot(v));
  }
  return angles;
}

// The deformation gradient as a 3 × 2 map from the rest frame to the world:
// F = [x_j − x_i, x_k − x_i] D_m⁻¹. Frame-free: its singular values and its
// polar factor U Vᵀ do not depend on how the current triangle's frame is chosen.
inline Eigen::Matrix<double, 3, 2> world_deformation(const Eigen::Matrix3d& corners,
                                                     const cl::lab05::TriangleRest& rest) {
  Eigen::Matrix<double, 3, 2> edges;
  edges.col(0) = corners.col(1) - corners.col(0);
  edges.col(1) = corners.col(2) - corners.col(0);
  return edges * rest.inverse_shape;
}

inline Eigen::Vector2d singular_values(const Eigen::Matrix<double, 3, 2>& f) {
  return Eigen::JacobiSVD<Eigen::Matrix<double, 3, 2>>(f).singularValues();
}

inline Eigen::Matrix<double, 3, 2> rotation_of(const Eigen::Matrix<double, 3, 2>& f) {
  // Thin unitaries need a dynamic size in Eigen: take the full U's first two columns.
  const Eigen::JacobiSVD<Eigen::Matrix<double, 3, 2>> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU().leftCols<2>() * svd.matrixV().transpose();
}

inline Eigen::Vector3d random_point(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  return scale * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
}

// A random triangle in a box of size `scale`, not too thin (every angle > 10°).
inline Eigen::Matrix3d random_triangle(std::mt19937_64& rng, double scale) {
  for (;;) {
    Eigen::Matrix3d corners;
    for (int a = 0; a < 3; ++a) corners.col(a) = random_point(rng, scale);
    if (angles_of(corners).minCoeff() > 10.0 * M_PI / 180.0) return corners;
  }
}

// Inverse masses from 1e-2 to 1e2.
inline Eigen::Vector3d random_inverse_masses(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> log_mass(-2.0, 2.0);
  return Eigen::Vector3d(std::pow(10.0, log_mass(rng)), std::pow(10.0, log_mass(rng)),
                         std::pow(10.0, log_mass(rng)));
}

}  // namespace lab05_test
