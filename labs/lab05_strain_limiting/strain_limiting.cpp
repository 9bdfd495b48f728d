// Lab 05 — your code. Read strain_limiting.h (the contract) and README.md (the
// derivation) first. Grade with:  ./course grade lab05
#include "strain_limiting.h"

#include <Eigen/Geometry>  // cross products
#include <Eigen/SVD>       // Eigen::JacobiSVD

#include "common/not_implemented.h"

namespace cl::lab05 {

// TODO(lab05.1) [8 pts] Limit one spring's strain σ = ‖x_i − x_j‖ / L to [σ_min, σ_max].
// Check the arguments (inverse masses finite and >= 0, L finite and > 0,
// 0 < σ_min <= σ_max, both finite) and throw std::invalid_argument otherwise.
// Compute σ and σ₀ = clamp(σ, σ_min, σ_max); inside the band return zeros.
// Otherwise move each end along n = (x_i − x_j)/ℓ by its inverse-mass share of
// (ℓ − σ₀L): Δx_i = −w_i/(w_i+w_j)(ℓ − σ₀L) n, Δx_j = +w_j/(w_i+w_j)(ℓ − σ₀L) n
// — lab 01's project_distance with rest length σ₀L does exactly this. Both
// ends pinned or coincident particles: zeros.
// Graded by tests/lab05_strain_limiting/test_limit_spring.cpp (4 pts) and
// test_runs.cpp (4 pts: your limiter inside the given step), and with lab05.2
// and lab05.3 by test_invalid_arguments.cpp (1 pt).
lab01::DistanceCorrection limit_spring(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j, double inv_mass_i,
                                       double inv_mass_j, double rest_length, double sigma_min, double sigma_max) {
  (void)x_i, (void)x_j, (void)inv_mass_i, (void)inv_mass_j, (void)rest_length, (void)sigma_min, (void)sigma_max;
  not_implemented("limit_spring", __FILE__);
}

// TODO(lab05.2) [2 pts] Limit a triangle's area ratio A / A_rest to [σ_min², σ_max²].
// Weights ω = (w_j w_k, w_i w_k, w_i w_j); if they sum to 0 (two or more corners
// pinned) or the triangle has zero area (triangle_frame returns false), return
// zeros. Otherwise r = A / rest_area, r₀ = clamp(r, σ_min², σ_max²); inside the
// band return zeros; else s = √(r₀ / r), c = Σ ω_a x_a / Σ ω_a and
// Δx_a = (s − 1)(x_a − c), column a of the result.
// Graded by tests/lab05_strain_limiting/test_limit_triangle_area.cpp.
Eigen::Matrix3d limit_triangle_area(const Eigen::Matrix3d& corners, const Eigen::Vector3d& inv_mass,
                                    double rest_area, double sigma_min, double sigma_max) {
  (void)corners, (void)inv_mass, (void)rest_area, (void)sigma_min, (void)sigma_max;
  not_implemented("limit_triangle_area", __FILE__);
}

// TODO(lab05.3) [5 pts] Limit a triangle's principal stretches to [σ_min, σ_max].
// Same weights and no-op cases as lab05.2; also throw std::invalid_argument
// when rest.shape (D_m) or rest.inverse_shape (D_m⁻¹) is not finite: both are
// used. Build the frame B (triangle_frame),
// D_s = Bᵀ [x_j − x_i, x_k − x_i], F = D_s · rest.inverse_shape and its SVD
// (Eigen::JacobiSVD<Eigen::Matrix2d> with ComputeFullU | ComputeFullV). Clamp
// both singular values; inside the band return zeros. Otherwise
// F₀ = U Σ₀ Vᵀ, rest corners X = (0, D_m.col(0), D_m.col(1)), centroids
// c = Σ ω_a x_a / Σ ω_a and X_c = Σ ω_a X_a / Σ ω_a, and
// Δx_a = c + B F₀ (X_a − X_c) − x_a.
// Graded by tests/lab05_strain_limiting/test_limit_triangle_stretch.cpp.
Eigen::Matrix3d limit_triangle_stretch(const Eigen::Matrix3d& corners, const Eigen::Vector3d& inv_mass,
                                       const TriangleRest& rest, double sigma_min, double sigma_max) {
  (void)corners, (void)inv_mass, (void)rest, (void)sigma_min, (void)sigma_max;
  not_implemented("limit_triangle_stretch", __FILE__);
}

}  // namespace cl::lab05
