#pragma once
// Lab 08 — extended position based dynamics (XPBD). The contract for the
// student's code. Derivation: labs/lab08_xpbd/README.md. Source: Macklin,
// Müller, Chentanez, "XPBD: Position-Based Simulation of Compliant Constrained
// Dynamics" (2016), §3 (the multiplier update, eq. 18) and §4 (the algorithm).
//
// Units: positions in m, velocities in m/s, inverse masses in 1/kg (0 =
// pinned), time in s, stiffness k in N/m, compliance α = 1/k in m/N, the
// time-scaled compliance α̃ = α/Δt² in 1/kg.
//
// The multiplier λ of a distance constraint C = ‖x_i − x_j‖ − L has units of
// force × Δt², i.e. N·s² (= kg·m): the constraint's force on particle i over
// the step is f_i = ∇_i C · λ / Δt² (N). A stretched spring (C > 0) ends a
// step with λ < 0: λ/Δt² is minus the spring's tension. At the converged
// step, C(x) = −α̃ λ, i.e. Hooke's law k·C = −λ/Δt².
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"
#include "pbd.h"

namespace cl::lab08 {

// Given: the compliance α = 1/k of a spring (m/N); 0 for a hard constraint
// (stiffness "inf"). Throws std::invalid_argument for a stiffness that is not
// > 0 (NaN included).
double compliance(const Spring& spring);

// The corrections of one XPBD projection and the multiplier's increment.
struct XpbdCorrection {
  Eigen::Vector3d dx_i = Eigen::Vector3d::Zero();  // m
  Eigen::Vector3d dx_j = Eigen::Vector3d::Zero();  // m
  double dlambda = 0.0;                            // N·s²
};

// TODO(lab08.1) — one XPBD projection of C = ‖x_i − x_j‖ − L, compliance α̃.
//
// With d = x_i − x_j, n = d/‖d‖ (so ∇_i C = n, ∇_j C = −n), C = ‖d‖ − L and
// `lambda` the multiplier accumulated so far in this step:
//     Δλ   = (−C − α̃ λ) / (w_i + w_j + α̃)
//     Δx_i = +w_i Δλ n
//     Δx_j = −w_j Δλ n
// After the move, C′ + α̃ (λ + Δλ) = 0 up to round-off, where
// C′ = ‖(x_i + Δx_i) − (x_j + Δx_j)‖ − L is the constraint after the move (the
// move is along d, so the length changes by exactly (w_i + w_j) Δλ). With α̃ = 0 and
// λ = 0 this is lab 01's project_distance. The centre of mass does not move.
//
// Degenerate input, never NaN:
//   - ‖d‖ = 0 (coincident particles): n is undefined; everything zero;
//   - w_i + w_j + α̃ = 0 (both pinned, hard): everything zero.
//   (Both pinned with α̃ > 0: no move, Δλ as the formula says.)
// Throws std::invalid_argument for a negative or non-finite inverse mass, rest
// length or α̃, or a non-finite λ.
XpbdCorrection project_distance_xpbd(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j, double inv_mass_i,
                                     double inv_mass_j, double rest_length, double alpha_tilde, double lambda);

struct XpbdSettings {
  double dt = 1.0 / 60.0;                    // step, s, finite and > 0
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  // m/s²
  int iterations = 10;                       // K Gauss-Seidel sweeps per step, >= 0
};

// TODO(lab08.2) — one XPBD step of size dt: the iteration loop.
//
// Predict exactly as lab 04 does (movable particles: v += Δt g, p = x + Δt v;
// pinned: p = x). Reset λ_s = 0 for every spring — once per step, never per
// sweep. Then K sweeps; each visits the springs in constraints.order and, for
// spring s with α̃_s = compliance(s) / Δt²,
//     (Δp_i, Δp_j, Δλ) = project_distance_xpbd(p_i, p_j, w_i, w_j, L_s, α̃_s, λ_s)
//     p_i += Δp_i,  p_j += Δp_j,  λ_s += Δλ.
// Finally v = (p − x)/Δt, x = p.
//
// `lambda` is resized to the number of springs (file order) and holds each
// spring's λ at the end of the step (N·s²; divide by Δt² for newtons). With
// every stiffness "inf" (α̃ = 0) the positions are lab 04's Gauss-Seidel
// pbd_step to round-off. One spring converges in one sweep; many springs
// converge as K grows to the implicit step
//     M (x⁺ − p) = Σ_s ∇C_s λ_s,   C_s(x⁺) + α̃_s λ_s = 0
// (exactly on a straight chain; otherwise up to the turning of ∇C within the
// step, which XPBD neglects — README.md).
//
// Shapes: particles.x and .v are 3 × n, updated in place; inv_mass has n
// entries. Throws std::invalid_argument for dt not finite or ≤ 0, iterations
// < 0, v / inv_mass not sized for n particles, an inverse mass that is
// negative or not finite, a spring index or an `order` entry out of range, a
// rest length that is negative or not finite, a stiffness not > 0, or an α̃
// that is not finite (a compliance over a Δt so small that α̃ overflows) —
// all of it checked before anything changes: on a throw the particles and
// `lambda` are left exactly as they were, so nothing the sweeps'
// project_distance_xpbd could reject is ever reached.
void xpbd_step(Particles& particles, const lab04::ConstraintSet& constraints, const XpbdSettings& settings,
               Eigen::VectorXd& lambda);

}  // namespace cl::lab08
