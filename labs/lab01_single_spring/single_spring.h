#pragma once
// Lab 01 — one spring, one projection. The contract for the student's code.
// Derivations: labs/lab01_single_spring/README.md. Source: Müller et al.,
// "Position Based Dynamics" (2007), §3.3 (constraint projection).
//
// Units: positions in m, inverse masses in 1/kg (0 = pinned), lengths in m.
#include <Eigen/Core>

namespace cl::lab01 {

// The two position corrections of one distance constraint.
struct DistanceCorrection {
  Eigen::Vector3d dx_i = Eigen::Vector3d::Zero();
  Eigen::Vector3d dx_j = Eigen::Vector3d::Zero();
};

// TODO(lab01.1) — project one distance constraint C = ‖x_i − x_j‖ − L = 0.
//
// Minimise ½ Σ m ‖Δx‖² subject to ‖(x_i + Δx_i) − (x_j + Δx_j)‖ = L. With
// d = x_i − x_j, n = d / ‖d‖ and C = ‖d‖ − L:
//     Δx_i = −w_i / (w_i + w_j) · C · n
//     Δx_j = +w_j / (w_i + w_j) · C · n
// so that ‖(x_i + Δx_i) − (x_j + Δx_j)‖ = L exactly (up to round-off).
//
// Degenerate input is a no-op (both corrections zero), never NaN:
//   - w_i + w_j = 0 (both ends pinned): nothing can move;
//   - ‖d‖ = 0 (coincident particles): the direction n is undefined.
// Throws std::invalid_argument for a negative or non-finite inverse mass or
// rest length.
DistanceCorrection project_distance(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j,
                                    double inv_mass_i, double inv_mass_j, double rest_length);

// TODO(lab01.2) — the general projection of one scalar constraint C(p) = 0 over
// n particles, linearised at p:
//     Δp_k = −C · w_k ∇_k C / Σ_j w_j ‖∇_j C‖²,   k = 0 … n−1
//
// Arguments: `constraint` is the value C(p); `gradients` is 3 × n, column k is
// ∇_k C; `inv_mass` has n entries (0 = pinned). Returns the 3 × n corrections.
// When the denominator Σ_j w_j ‖∇_j C‖² is 0 (every particle pinned, or a zero
// gradient) the result is all zeros. Throws std::invalid_argument when the
// shapes disagree, or for a negative or non-finite inverse mass, a non-finite
// C or gradient.
Eigen::Matrix3Xd project_constraint(double constraint, const Eigen::Matrix3Xd& gradients,
                                    const Eigen::VectorXd& inv_mass);

}  // namespace cl::lab01
