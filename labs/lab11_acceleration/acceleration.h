#pragma once
// Lab 11 — accelerating projective dynamics and Jacobi PBD. The contract for
// the student's code. Derivations: labs/lab11_acceleration/README.md.
// Sources:
//   H. Wang, "A Chebyshev Semi-Iterative Approach for Accelerating Projective
//   and Position-based Dynamics", ACM TOG 34(6) (SIGGRAPH Asia 2015): the
//   weights ω, the accelerated update with under-relaxation γ and delay S, and
//   the estimate of the spectral radius ρ from a run of plain iterations;
//   T. Liu, S. Bouaziz, L. Kavan, "Quasi-Newton Methods for Real-Time
//   Simulation of Hyperelastic Materials", ACM TOG 36(3) (2017): projective
//   dynamics as a quasi-Newton method whose Hessian guess is PD's constant
//   matrix A = M/Δt² + Σ k SᵀS, and L-BFGS on top of it (the two-loop
//   recursion with A⁻¹ as the initial inverse Hessian).
//
// A convergent fixed-point iteration q̂^(k+1) = F(q^(k)) (one PD local/global
// iteration, lab 06; one Jacobi sweep, lab 03) behaves near its fixed point
// like a linear iteration whose error shrinks by the spectral radius ρ < 1 per
// iteration. The Chebyshev semi-iterative method replaces q^(k+1) = q̂^(k+1) by
//     q^(k+1) = ω_(k+1) (γ (q̂^(k+1) − q^(k)) + q^(k) − q^(k−1)) + q^(k−1).
//
// Units: positions in m; ρ, ω, γ are pure numbers. Shapes: positions are 3 × n
// (one column per particle); the L-BFGS vectors are stacked over the unknowns,
// 3 entries (x, y, z) per movable particle (cl::gather_stacked, common/sparse.h).
#include <functional>
#include <vector>

#include <Eigen/Core>

namespace cl::lab11 {

// TODO(lab11.1) — the Chebyshev weight of the j-th iteration of an accelerated
// run, counted from its start or its last restart (j = 1, 2, 3, …):
//
//     ω_1 = 1,   ω_2 = 2 / (2 − ρ²),   ω_j = 4 / (4 − ρ² ω_(j−1))  (j ≥ 3)
//
// previous_omega is ω_(j−1) (read only for j ≥ 3). From ω_2, the largest, the
// weights decrease to ω_∞ = 2 / (1 + √(1 − ρ²)) < 2. ρ = 0 gives ω_j = 1 for every j.
// Throws std::invalid_argument for j < 1, ρ not finite or outside [0, 1), and
// (j ≥ 3) previous_omega not finite or outside [1, 2).
double chebyshev_weight(int j, double rho, double previous_omega);

// TODO(lab11.2) — the accelerated update, column by column:
//
//     q_next = ω (γ (q_hat − q) + q − q_previous) + q_previous
//
// computed in the expanded form  ω γ q_hat + ω (1 − γ) q + (1 − ω) q_previous
// (the same number in exact arithmetic), so that ω = γ = 1 returns q_hat bit
// for bit: a run with ρ = 0 is the plain iteration exactly.
// q_hat: the plain iterate F(q); q: the current iterate; q_previous: the one
// before (all 3 × n). Throws std::invalid_argument when the shapes differ,
// ω is not finite or outside [1, 2), or γ is not finite or outside (0, 2).
Eigen::Matrix3Xd chebyshev_update(const Eigen::Matrix3Xd& q_hat, const Eigen::Matrix3Xd& q,
                                  const Eigen::Matrix3Xd& q_previous, double omega, double gamma);

// TODO(lab11.3) — the spectral radius of a plain run, estimated from the
// lengths of its updates e_k = ‖q^(k+1) − q^(k)‖ (k = 0 … n−1):
//
//     ρ ≈ (e_(n−1) / e_(n−1−w))^(1/w),   w = ⌊n/2⌋,
//
// the geometric mean of the last w ratios e_(k+1)/e_k: the first half of the
// run is discarded (the fast modes and the nonlinear start are still dying
// out there) and a mean over many ratios smooths the oscillation of modes of
// nearly equal size (README.md, "Estimating ρ"). The result is the measured
// rate: it may be ≥ 1 for a run that does not converge (the caller decides).
// When e_(n−1−w) or e_(n−1) is 0 the run converged exactly: returns 0.
// Throws std::invalid_argument for fewer than 2 lengths or a length that is
// negative or not finite.
double estimate_spectral_radius(const std::vector<double>& update_norms);

// TODO(lab11.4) — the restart rule. The accelerated iterate is rejected (the
// plain iterate is taken instead and the weights restart at ω = 1) when its
// objective is not finite or rose:
//
//     restart ⇔ objective_after is NaN or ±inf, or
//               objective_after > objective_before + slack · |objective_before|
//
// slack (≥ 0, e.g. 1e-12) lets round-off through without a restart.
// Throws std::invalid_argument for objective_before not finite, or slack
// negative or not finite.
bool restart_needed(double objective_before, double objective_after, double slack);

// One L-BFGS pair: s = x_(i+1) − x_i, y = ∇g(x_(i+1)) − ∇g(x_i), stacked.
struct CurvaturePair {
  Eigen::VectorXd s;
  Eigen::VectorXd y;
};

// v ↦ H₀ v, the initial inverse Hessian applied to a stacked vector (here A⁻¹ v:
// one prefactored solve per coordinate, given code).
using InverseApply = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

// TODO(lab11.5) — the L-BFGS direction d = −H ∇g by the two-loop recursion
// (Nocedal and Wright, Algorithm 7.4; Liu et al. 2017, Algorithm 1):
//
//     q ← ∇g
//     for i = newest … oldest:  α_i = (s_iᵀ q) / (s_iᵀ y_i);  q ← q − α_i y_i
//     r ← H₀ q                                    (initial_inverse(q))
//     for i = oldest … newest:  β = (y_iᵀ r) / (s_iᵀ y_i);  r ← r + (α_i − β) s_i
//     d = −r
//
// pairs are ordered oldest first. A pair with sᵀy ≤ 0 (or not finite) is
// skipped in both loops: its BFGS update would not keep H positive definite
// and d might not descend (README.md). With no pairs, d = −H₀ ∇g: with H₀ = A⁻¹
// and a full step that is one projective dynamics iteration.
// Throws std::invalid_argument when a pair's s or y is not the gradient's size.
Eigen::VectorXd lbfgs_direction(const Eigen::VectorXd& gradient, const std::vector<CurvaturePair>& pairs,
                                const InverseApply& initial_inverse);

}  // namespace cl::lab11
