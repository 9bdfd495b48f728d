#pragma once
// Lab 06 — projective dynamics. The contract for the student's code.
// Derivation: labs/lab06_projective_dynamics/README.md. Source: Bouaziz et al.,
// "Projective Dynamics: Fusing Constraint Projections for Fast Simulation"
// (2014), §3 (the local/global alternation) and §4 (springs).
//
// One implicit-Euler step of size Δt minimises over the positions x
//     g(x) = ‖x − y‖²_M / (2Δt²) + E(x),   E(x) = Σ_e k_e/2 (‖x_i − x_j‖ − L_e)²,
// where y = x_old + Δt v + Δt² g is the prediction. Written with the projected
// springs d_e (‖d_e‖ = L_e), E(x) = min over d of Σ_e k_e/2 ‖(x_i − x_j) − d_e‖²:
// for fixed d it is quadratic in x, and its Hessian
//     A = M/Δt² + Σ_e k_e S_eᵀ S_e          (S_e x = x_i − x_j)
// does not depend on x or d, so it is factored once per scene.
//
// Units: positions in m, inverse masses in 1/kg (0 = pinned), stiffness in N/m,
// time in s. Shapes: per-particle arrays are 3 × n (one column per particle);
// arrays over the unknowns are RowsX3 (one row per movable particle, in the
// order of MovableMap, common/sparse.h). Pinned particles are not unknowns:
// their positions enter the right-hand side.
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/sparse.h"

namespace cl::lab06 {

// What stays fixed during a scene. Build it with make_problem (given code,
// problem.cpp), which validates everything below.
struct Problem {
  std::vector<Spring> springs;  // k_e finite and > 0 (N/m), L_e >= 0 (m), i != j
  Eigen::VectorXd inv_mass;     // 1/kg per particle; 0 = pinned
  MovableMap map;               // make_movable_map(inv_mass): the unknowns
  double dt = 1.0 / 60.0;       // s, finite and > 0
};

// Given code. Throws std::invalid_argument naming the spring for an index out
// of range, i == j, a negative or non-finite rest length, or a stiffness that
// is not finite or ≤ 0 ("inf" is a hard constraint: lab 07), and for dt that
// is not finite or ≤ 0 or an inverse mass that is negative or not finite.
Problem make_problem(const Eigen::VectorXd& inv_mass, std::vector<Spring> springs, double dt);

// TODO(lab06.1) — the local step: each spring's projection onto its rest length.
//
//     d_e = L_e (x_i − x_j) / ‖x_i − x_j‖
//
// the point of the sphere of radius L_e closest to x_i − x_j. The ends count
// as coincident when the computed length (Eigen's norm(), the root of the
// squared length) is 0 — for ends that are equal, and for ends closer than
// about 1e-162 m, whose squared length underflows to 0. Every point of the
// sphere is then equally close: return d_e = L_e (1, 0, 0). Rest length 0 gives
// d_e = 0. (The given Newton code uses the same rule and direction.)
//
// x: 3 × n positions. Returns 3 × m, column e for springs[e]. Never NaN for
// finite x. Throws std::invalid_argument for a spring index out of range.
Eigen::Matrix3Xd local_step(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

// TODO(lab06.2) — the global matrix, over the unknowns only:
//
//     A = M/Δt² + Σ_e k_e S_eᵀ S_e
//
// n_u × n_u (n_u = problem.map.unknowns()), the same for x, y and z. Row u
// gets m_u/Δt² (m = 1/inv_mass) on the diagonal; a spring between unknowns a
// and b adds k_e at (a, a) and (b, b) and −k_e at (a, b) and (b, a); a spring
// with one pinned end adds k_e at its movable end's diagonal only; a spring
// with both ends pinned adds nothing. Symmetric positive definite.
// Build it from triplets with cl::assemble (common/sparse.h).
// Throws std::invalid_argument for dt not finite or ≤ 0, or a stiffness that
// is not finite or ≤ 0 (naming the spring).
SparseMatrix system_matrix(const Problem& problem);

// TODO(lab06.3) — the right-hand side of A x = b for fixed projections d:
//
//     b = M y / Δt² + Σ_e k_e S_eᵀ d_e     (then the pinned ends moved over)
//
// For a spring e = (i, j) with projection d_e:
//     i and j movable:      b_i += k_e d_e,          b_j −= k_e d_e
//     i movable, j pinned:  b_i += k_e (x_j + d_e)
//     i pinned, j movable:  b_j += k_e (x_i − d_e)
// where a pinned particle's position is its column of y (the prediction of a
// pinned particle is where it is held).
// y: 3 × n, d: 3 × m (from local_step). Returns n_u × 3 (RowsX3).
// Throws std::invalid_argument when y or d have the wrong number of columns.
RowsX3 right_hand_side(const Problem& problem, const Eigen::Matrix3Xd& y, const Eigen::Matrix3Xd& d);

// TODO(lab06.4) — the global step: solve A x = b for all three coordinates
// with the stored factorization (one pass over the factor: factor.solve3),
// b = right_hand_side(problem, y, d). Returns 3 × n positions: the solution
// in the movable columns, y's columns (the held positions) in the pinned ones.
// The result minimises Σ m‖x − y‖²/(2Δt²) + Σ_e k_e/2 ‖(x_i − x_j) − d_e‖².
// Throws std::invalid_argument when factor holds no factor of the right size
// (factor.ok() false, or factor.size() != n_u) or y / d are mis-sized.
Eigen::Matrix3Xd global_step(const Problem& problem, const SpdFactorization& factor, const Eigen::Matrix3Xd& y,
                             const Eigen::Matrix3Xd& d);

// TODO(lab06.5) — the objective both projective dynamics and Newton minimise:
//
//     g(x) = Σ_{movable p} m_p ‖x_p − y_p‖² / (2Δt²) + Σ_e k_e/2 (‖x_i − x_j‖ − L_e)²   (J)
//
// x, y: 3 × n. Pinned particles add no inertia term (their springs count).
// Throws std::invalid_argument when x or y have the wrong number of columns.
double objective(const Problem& problem, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y);

}  // namespace cl::lab06
