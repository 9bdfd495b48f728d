// Lab 05 — given code: a triangle's own 2-D frame and its rest shape D_m.
#include <algorithm>
#include <stdexcept>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "strain_limiting.h"

namespace cl::lab05 {

bool triangle_frame(const Eigen::Matrix3d& corners, Eigen::Matrix<double, 3, 2>& basis) {
  const Eigen::Vector3d edge_ij = corners.col(1) - corners.col(0);
  const Eigen::Vector3d edge_ik = corners.col(2) - corners.col(0);
  const double twice_area = edge_ij.cross(edge_ik).norm();
  const double longest = std::max({edge_ij.squaredNorm(), edge_ik.squaredNorm(),
                                   (corners.col(2) - corners.col(1)).squaredNorm()});
  // The scene loader's zero-area test, area <= 1e-12 × longest²; NaN fails it too.
  if (!(0.5 * twice_area > 1e-12 * longest)) return false;
  const Eigen::Vector3d e1 = edge_ij / edge_ij.norm();
  const Eigen::Vector3d across = edge_ik - edge_ik.dot(e1) * e1;
  basis.col(0) = e1;
  basis.col(1) = across / across.norm();
  return true;
}

TriangleRest make_triangle_rest(const Eigen::Matrix3d& corners) {
  if (!corners.allFinite()) throw std::invalid_argument("make_triangle_rest: a corner is not finite");
  Eigen::Matrix<double, 3, 2> basis;
  if (!triangle_frame(corners, basis)) {
    throw std::invalid_argument("make_triangle_rest: zero area (collinear or coincident corners)");
  }
  Eigen::Matrix<double, 3, 2> edges;
  edges.col(0) = corners.col(1) - corners.col(0);
  edges.col(1) = corners.col(2) - corners.col(0);
  TriangleRest rest;
  rest.shape = basis.transpose() * edges;
  rest.shape(1, 0) = 0.0;  // e2 ⟂ (x_j − x_i) exactly: drop the round-off
  rest.inverse_shape = rest.shape.inverse();
  rest.area = 0.5 * rest.shape.determinant();
  return rest;
}

}  // namespace cl::lab05
