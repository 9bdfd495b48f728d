#pragma once
// Lab 05 — strain limiting. The contract for the student's code.
// Derivation: labs/lab05_strain_limiting/README.md. Sources: Provot, "Deformation
// constraints in a mass-spring model to describe rigid cloth behavior" (1995)
// for springs; Thomaszewski, Pabst and Straßer, "Continuum-based strain
// limiting" (2009) for triangles.
//
// Every limiter is an inequality version of lab 01's projection: nothing moves
// while the strain is inside the band [sigma_min, sigma_max]; outside it, the
// smallest mass-weighted move brings it back to the nearer bound.
//
// Units: positions in m, inverse masses in 1/kg (0 = pinned), lengths in m,
// areas in m². sigma_min and sigma_max are ratios (current / rest), no unit.
// A triangle's corners are the columns of a 3 × 3 matrix: corners.col(0) = x_i,
// corners.col(1) = x_j, corners.col(2) = x_k; its corrections come back the
// same way.
#include <Eigen/Core>

#include "single_spring.h"

namespace cl::lab05 {

// ------------------------------------------------------------------ given code
// (triangle_rest.cpp; read it, it shows how a triangle's own 2-D frame is built)

// The rest shape of a triangle in its own 2-D frame (see triangle_frame):
//     D_m = [X_j − X_i, X_k − X_i]   (2 × 2, columns are the rest edges, m)
// with X_i = 0, so the rest corners in 2-D are 0, D_m.col(0), D_m.col(1).
// D_m is upper triangular with a positive diagonal, so det D_m = 2 × area > 0.
struct TriangleRest {
  Eigen::Matrix2d shape = Eigen::Matrix2d::Identity();          // D_m, m
  Eigen::Matrix2d inverse_shape = Eigen::Matrix2d::Identity();  // D_m⁻¹, 1/m
  double area = 0.5;                                            // ½ det D_m, m²
};

// A triangle's own 2-D frame: the orthonormal columns
//     e1 = (x_j − x_i) / ‖x_j − x_i‖,
//     e2 = the part of (x_k − x_i) perpendicular to e1, normalised,
// so that a corner's frame coordinates are basisᵀ (x − x_i) and the frame's
// normal e1 × e2 points along (x_j − x_i) × (x_k − x_i). Returns false, and
// leaves `basis` unchanged, when the triangle has zero area up to round-off:
// area <= 1e-12 × (longest edge)², the test the scene loader uses.
bool triangle_frame(const Eigen::Matrix3d& corners, Eigen::Matrix<double, 3, 2>& basis);

// D_m, D_m⁻¹ and the area of the triangle `corners`, in its own frame.
// Throws std::invalid_argument for a zero-area triangle or a non-finite corner.
TriangleRest make_triangle_rest(const Eigen::Matrix3d& corners);

// ------------------------------------------------------------------ your code

// TODO(lab05.1) — limit the strain σ = ‖x_i − x_j‖ / L of one spring to the band
// [sigma_min, sigma_max].
//
// With d = x_i − x_j, ℓ = ‖d‖, n = d / ℓ, σ = ℓ / L and σ₀ = clamp(σ, σ_min, σ_max):
//     Δx_i = −w_i / (w_i + w_j) · (ℓ − σ₀ L) · n
//     Δx_j = +w_j / (w_i + w_j) · (ℓ − σ₀ L) · n
// so the new length is σ₀ L: lab 01's projection onto the rest length σ₀ L
// (you may call cl::lab01::project_distance). Inside the band (σ₀ = σ) both
// corrections are exactly zero.
//
// Degenerate input is a no-op (both corrections zero), never NaN:
//   - w_i + w_j = 0 (both ends pinned);
//   - ℓ = 0 (coincident particles: σ = 0 is below the band, but no direction
//     to push them apart along is defined).
// A pinned end (w = 0) never moves; the other takes the whole correction.
// Throws std::invalid_argument for a negative or non-finite inverse mass, a
// rest length that is not finite or ≤ 0 (σ is undefined for L = 0), a
// sigma_min that is not finite or ≤ 0, a non-finite sigma_max, or
// sigma_min > sigma_max.
lab01::DistanceCorrection limit_spring(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j, double inv_mass_i,
                                       double inv_mass_j, double rest_length, double sigma_min, double sigma_max);

// The mass-weighted centroid that both triangle limiters scale about. With
// masses m_a = 1 / w_a it is c = Σ m_a x_a / Σ m_a; multiplied through by
// w_i w_j w_k so that nothing is divided by an inverse mass:
//     c = Σ_a ω_a x_a / Σ_a ω_a,   ω_i = w_j w_k,  ω_j = w_i w_k,  ω_k = w_i w_j.
// One pinned corner (w = 0) makes c that corner, so it stays put. Two or three
// pinned corners make every ω zero and c undefined. Both limiters are then a
// no-op, by this lab's convention: the area limiter scales about c, and no
// scaled copy of a triangle keeps two of its corners in place, so it has no
// move at all; the stretch limiter could still reach a limited F by moving
// the one free corner, but only by giving that corner the whole correction, a
// different rule from the centroid's that would pull a cloth's edge along its
// pins. A triangle with two pinned corners is left to its springs.

// TODO(lab05.2) — limit a triangle's area ratio A / A_rest to the band
// [sigma_min², sigma_max²] by scaling it about its mass-weighted centroid c.
//
// With A = ½ ‖(x_j − x_i) × (x_k − x_i)‖, r = A / rest_area and
// r₀ = clamp(r, sigma_min², sigma_max²), the scale s = √(r₀ / r) gives
//     Δx_a = (s − 1)(x_a − c),   a = i, j, k,
// a triangle similar to the input (same angles, same normal) with area
// r₀ · rest_area and the same mass-weighted centroid. Inside the band every
// correction is exactly zero.
//
// No-op (all zeros): two or three pinned corners (see above), or a triangle of
// zero area up to round-off (triangle_frame's test: scaling cannot give it an
// area). Throws std::invalid_argument for a negative or non-finite inverse
// mass, a rest_area that is not finite or ≤ 0, or sigma_min / sigma_max as
// limit_spring says.
Eigen::Matrix3d limit_triangle_area(const Eigen::Matrix3d& corners, const Eigen::Vector3d& inv_mass,
                                    double rest_area, double sigma_min, double sigma_max);

// TODO(lab05.3) — limit a triangle's principal stretches to [sigma_min, sigma_max].
//
// In the current triangle's own frame (triangle_frame: basis B, 3 × 2):
//     D_s = Bᵀ [x_j − x_i, x_k − x_i]     (2 × 2)
//     F   = D_s D_m⁻¹ = U Σ Vᵀ             (SVD, Σ = diag(σ_1, σ_2), σ ≥ 0)
//     F₀  = U Σ₀ Vᵀ,  Σ₀ = clamp(Σ, sigma_min, sigma_max) entry by entry
// F₀ has the same rotation as F (its polar factor R = U Vᵀ). Rebuild the
// corners from the rest corners X_a (0, D_m.col(0), D_m.col(1)) about the
// mass-weighted centroids c (current) and X_c (rest, same weights ω_a):
//     x_a' = c + B F₀ (X_a − X_c),   Δx_a = x_a' − x_a.
// Inside the band (both σ in [sigma_min, sigma_max]) every correction is
// exactly zero.
//
// Inverted triangles: in 3-D a triangle is measured in its own frame, whose
// normal follows the corners, so det D_s > 0 and det F > 0 always. A triangle
// turned over (x_k pushed through the edge x_i x_j) is the same triangle seen
// from its other side: it is limited like any other and stays turned over (the
// result keeps its normal); if its edge lengths are the rest ones nothing moves.
// Zero-area triangles (triangle_frame returns false: collinear or coincident
// corners) have no frame and no direction to open them in: a no-op (all zeros).
// Also a no-op: two or three pinned corners (the convention above).
// Both parts of the rest shape are used: D_m⁻¹ (rest.inverse_shape) to form F,
// D_m (rest.shape) for the rest corners X_a. Throws std::invalid_argument for a
// negative or non-finite inverse mass, a rest whose area is not finite or ≤ 0
// or whose D_m or D_m⁻¹ is not finite, or sigma_min / sigma_max as
// limit_spring says. (That the two are inverses of each other is triangle_rest's
// promise; the limiter does not check it.)
Eigen::Matrix3d limit_triangle_stretch(const Eigen::Matrix3d& corners, const Eigen::Vector3d& inv_mass,
                                       const TriangleRest& rest, double sigma_min, double sigma_max);

}  // namespace cl::lab05
