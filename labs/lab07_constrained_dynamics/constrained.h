#pragma once
// Lab 07 — constrained dynamics: the KKT system, solved primal-dual and by its
// Schur complement, down to infinite stiffness. The contract for the student's
// code. Derivation: labs/lab07_constrained_dynamics/README.md. Source: the
// course's seed notes and slides P30–33 ("Constrained Dynamics"); for the
// compliant form see also Servin, Lacoursière and Melin, "Interactive
// simulation of elastic deformable materials" (2006), and Tournier et al.,
// "Stable Constrained Dynamics" (2015), §3.
//
// Units: positions in m, velocities in m/s, inverse masses in 1/kg (0 =
// pinned), time in s, gravity in m/s², compliance in m/N (= 1/stiffness),
// multipliers λ in N.
//
// Notation. n particles, u of them movable (the unknowns, see
// common/sparse.h: MovableMap), m springs in file order. Vectors over the
// unknowns are "stacked": 3u entries, unknown k's (x, y, z) at 3k, 3k+1, 3k+2.
//   φ_e = ‖x_i − x_j‖ − L_e                      (m entries, m)
//   J   = ∂φ/∂x over the movable unknowns         (m × 3u; pinned columns dropped)
//   C   = diag(c_e), c_e = 1/k_e, 0 for a hard ("inf") spring   (m/N)
//   W   = M⁻¹, diagonal, each unknown's inverse mass three times   (1/kg)
// The step (implicit Euler with the constraint linearised at x):
//   [ M     −ΔtJᵀ ] [ v_new ]   [ Mv + ΔtMg ]
//   [ ΔtJ    C    ] [ λ     ] = [ −φ        ]
// then x ← x + Δt v_new.
//
// Sign convention for λ. The first row says M(v_new − v)/Δt = Mg + Jᵀλ: the
// constraint force on the particles is Jᵀλ. The second row says
// λ = −C⁻¹(φ + ΔtJv_new), minus the stiffness times the linearised stretch at
// the end of the step. So λ < 0 is tension (a stretched spring pulls its ends
// together), λ > 0 compression, and |λ_e| is the force the spring carries, in
// newtons. A bead of mass m hanging at rest from a pin has λ = −mg.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"
#include "common/sparse.h"

namespace cl::lab07 {

// Everything one step needs, evaluated at the current state (the given
// function linearize() in step.h fills it from particles and springs).
struct LinearizedStep {
  SparseMatrix jacobian;       // J, m × 3u
  Eigen::VectorXd phi;         // φ, m entries, m
  // c_e (m/N), m entries with 0 for a hard constraint; or EMPTY when every
  // constraint is hard: the scene then has no compliance block at all.
  Eigen::VectorXd compliance;
  Eigen::VectorXd inv_mass;    // W's diagonal, 3u entries, each > 0
  Eigen::VectorXd velocity;    // v, stacked, 3u entries
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};
  double dt = 1.0 / 60.0;      // s, > 0
};

// The primal-dual system as written above: `matrix` is (3u + m) × (3u + m),
// unknowns ordered [v_new; λ]; `rhs` has 3u + m entries.
struct KktSystem {
  SparseMatrix matrix;
  Eigen::VectorXd rhs;
};

// The outcome of one solve.
struct StepSolution {
  Eigen::VectorXd velocity;  // v_new, stacked, 3u entries (empty when !ok)
  Eigen::VectorXd lambda;    // λ, m entries, N, file order (empty when !ok)
  bool ok = false;           // false: the system could not be solved (see problem)
  std::string problem;       // one line saying why, when !ok
};

// TODO(lab07.1) — the constraint values φ_e = ‖x_i − x_j‖ − L_e, one per spring
// in file order (m). x is 3 × n. Throws std::invalid_argument for an index
// out of range, i == j, or a negative or non-finite rest length.
Eigen::VectorXd constraint_values(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

// TODO(lab07.1) — the Jacobian J = ∂φ/∂x, m × 3u, over the movable unknowns.
// Row e, with n_e = (x_i − x_j)/‖x_i − x_j‖: +n_eᵀ in the three columns of
// i's unknown and −n_eᵀ in those of j's. A pinned end (map.unknown_of = −1) has
// no columns: its entries are dropped. Coincident particles (‖x_i − x_j‖ = 0)
// have no direction: the row is left empty (documented no-op, never NaN).
// Throws std::invalid_argument like constraint_values, and when map does not
// have one entry per particle.
SparseMatrix constraint_jacobian(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs,
                                 const MovableMap& map);

// TODO(lab07.2) — assemble the KKT matrix and right-hand side above, with
// M = diag(1 / inv_mass). The lower-right block holds C's non-zero entries
// only (none at all when step.compliance is empty). Throws
// std::invalid_argument when the sizes disagree, dt is not finite or ≤ 0, or
// an inverse mass is not finite or ≤ 0.
KktSystem kkt_system(const LinearizedStep& step);

// TODO(lab07.3) — the primal-dual solve. With every c_e > 0, negating the
// constraint rows makes the matrix symmetric quasi-definite,
//     S = [M, −ΔtJᵀ; −ΔtJ, −C]   (M and C positive definite),
// which has an LDLᵀ in any symmetric ordering with no pivoting (Vanderbei
// 1995; README.md). Take the multipliers first: with H the upper-left block
// and B = ΔtJ the lower-left one, factor R = H + Bᵀ C⁻¹ B (SPD) with
// cl::SpdFactorization, v_new = R⁻¹ (b₁ + Bᵀ C⁻¹ b₂), λ = C⁻¹ (b₂ − B v_new).
// With some c_e = 0 the lower-right block is singular and S is not
// quasi-definite: factor system.matrix with a sparse LU with partial
// pivoting (Eigen::SparseLU), as also when R is refused or its answer
// misses. Tell the two apart from the matrix: S exactly symmetric, its
// lower-right block diagonal with every entry < 0, and its upper-left block
// with a positive diagonal that strictly dominates each of its rows
// (positive definite by Gershgorin; lab 09's M − Δt²K_g need not be).
// `velocity_unknowns` is 3u: the
// first 3u entries of the solution are v_new, the rest λ. Returns ok = false
// with a problem line (never NaN) when the factorization fails, the solution
// z is not finite, or it misses the system, ‖Az − b‖∞ > 1e-8 (‖A‖∞‖z‖∞ +
// ‖b‖∞) (a pivot that is zero only up to round-off); the LDLᵀ's answer that
// misses is not final: the LU decides. Two of these checks are defensive, and
// no graded case tells them apart: the test that every entry of the
// lower-right block is < 0, and the residual check of the LDLᵀ's answer. Left
// out, a hard constraint's 1/c_e = inf makes that answer not finite, and the
// LU answers instead; they keep the LDLᵀ from deciding where it cannot. A redundant but
// consistent set of hard constraints can still pass: v_new is then right (it
// is unique) and λ one of infinitely many splits (README.md). Throws
// std::invalid_argument when the matrix is not square, the rhs has the wrong
// size, or velocity_unknowns is outside [0, size].
StepSolution solve_kkt(const KktSystem& system, Eigen::Index velocity_unknowns);

// TODO(lab07.4) — the Schur-complement solve: eliminate v_new,
//     (Δt² J W Jᵀ + C) λ = −φ − ΔtJ(v + Δtg),
//     v_new = v + Δtg + Δt W Jᵀ λ,
// factoring the m × m matrix with cl::SpdFactorization (it is symmetric
// positive definite when C > 0 or J has full row rank). When the factorization
// refuses (redundant hard constraints: the matrix is singular) returns
// ok = false with a problem line that contains "singular". With no springs
// (m = 0) returns v_new = v + Δtg and an empty λ (graded; returning early is
// defensive: cl::SpdFactorization of the 0 × 0 matrix gives the same). Throws
// std::invalid_argument like kkt_system.
StepSolution solve_schur(const LinearizedStep& step);

// TODO(lab07.5) — the update: x ← x + Δt v_new for every movable particle
// (velocity is stacked over map's unknowns) and v ← v_new; pinned particles
// keep their position and get v = 0. Throws std::invalid_argument, before
// changing anything, when the sizes disagree or dt is not finite or ≤ 0.
void update_positions(Particles& particles, const MovableMap& map, const Eigen::VectorXd& velocity, double dt);

}  // namespace cl::lab07
