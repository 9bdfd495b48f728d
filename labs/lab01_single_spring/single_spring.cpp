// Lab 01 — your code. Read single_spring.h (the contract) and README.md (the
// derivation) first. Grade with:  ./course grade lab01
#include "single_spring.h"

#include "common/not_implemented.h"

namespace cl::lab01 {

// TODO(lab01.1) [9 pts] Project one distance constraint.
// Compute d = x_i − x_j, its length, C = length − rest_length, and move each end
// along n = d / length, the lighter (larger inverse mass) end further. Return
// zeros when both ends are pinned or the particles coincide; throw
// std::invalid_argument for an inverse mass or rest length that is negative or
// not finite (NaN, inf) — check with std::isfinite from <cmath>.
// Graded by tests/lab01_single_spring/test_project_distance.cpp.
DistanceCorrection project_distance(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j,
                                    double inv_mass_i, double inv_mass_j, double rest_length) {
  (void)x_i, (void)x_j, (void)inv_mass_i, (void)inv_mass_j, (void)rest_length;
  not_implemented("project_distance", __FILE__);
}

// TODO(lab01.2) [3 pts] The general projection Δp_k = −C · w_k ∇_k C / Σ_j w_j ‖∇_j C‖².
// Check the shapes (one inverse mass per gradient column), that C and the
// gradients are finite and the inverse masses finite and >= 0 (else throw
// std::invalid_argument); form the denominator, return zeros when it is 0.
// The result is 3 x n: give it its size before writing into its columns.
// Graded by tests/lab01_single_spring/test_project_constraint.cpp.
Eigen::Matrix3Xd project_constraint(double constraint, const Eigen::Matrix3Xd& gradients,
                                    const Eigen::VectorXd& inv_mass) {
  (void)constraint, (void)gradients, (void)inv_mass;
  not_implemented("project_constraint", __FILE__);
}

}  // namespace cl::lab01
