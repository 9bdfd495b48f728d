// Lab 07 — your code. Read constrained.h (the contract) and README.md (the
// derivation) first. Grade with:  ./course grade lab07
#include "constrained.h"

#include <Eigen/SparseLU>

#include "common/not_implemented.h"

namespace cl::lab07 {

// TODO(lab07.1) [3 pts] The constraint values, one per spring in file order:
//     φ_e = ‖x_i − x_j‖ − L_e   (m)
// Throw std::invalid_argument for an index out of range, i == j, or a rest
// length that is negative or not finite.
// Graded by tests/lab07_constrained_dynamics/test_jacobian.cpp (with the Jacobian).
Eigen::VectorXd constraint_values(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  (void)x, (void)springs;
  not_implemented("constraint_values", __FILE__);
}

// TODO(lab07.1) The Jacobian J = ∂φ/∂x over the movable unknowns, m × 3u.
// For spring e with d = x_i − x_j and n = d/‖d‖: row e holds +nᵀ in columns
// 3·map.unknown_of[i] + (0, 1, 2) and −nᵀ in those of j. A pinned end
// (unknown_of = −1) contributes nothing; coincident ends (‖d‖ = 0) leave the
// row empty. Collect cl::Triplet entries and call cl::assemble(m, 3u, triplets).
// Check the springs as constraint_values does, and that map has one entry per particle.
// Graded by tests/lab07_constrained_dynamics/test_jacobian.cpp: central
// differences of φ to 1e-7, pinned columns dropped.
SparseMatrix constraint_jacobian(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs,
                                 const MovableMap& map) {
  (void)x, (void)springs, (void)map;
  not_implemented("constraint_jacobian", __FILE__);
}

// TODO(lab07.2) [2 pts] The KKT matrix and right-hand side, unknowns [v_new; λ]:
//     [ M     −ΔtJᵀ ] [ v_new ]   [ M(v + Δt g) ]
//     [ ΔtJ    C    ] [ λ     ] = [ −φ          ]
// M = diag(1/step.inv_mass) (3u entries). C's entries go in only where they are
// non-zero, and not at all when step.compliance is empty (every spring hard).
// Throw std::invalid_argument when sizes disagree (jacobian m × 3u, phi m,
// compliance m or empty, inv_mass and velocity 3u), dt is not finite or ≤ 0,
// or an inverse mass is not finite or ≤ 0.
// Graded by tests/lab07_constrained_dynamics/test_kkt.cpp.
KktSystem kkt_system(const LinearizedStep& step) {
  (void)step;
  not_implemented("kkt_system", __FILE__);
}

// TODO(lab07.3) [2 pts] Solve the KKT system. When every c_e > 0, negating
// the constraint rows makes it S = [M, −ΔtJᵀ; −ΔtJ, −C], symmetric
// quasi-definite, whose LDLᵀ needs no pivoting in any order (README.md,
// "Method 1"). Take the order "multipliers first": with H the upper-left
// block and B = ΔtJ the lower-left one (the upper right is −Bᵀ), factor
// R = H + Bᵀ C⁻¹ B with cl::SpdFactorization, solve R v_new = b₁ + Bᵀ C⁻¹ b₂,
// then λ = C⁻¹ (b₂ − B v_new). Otherwise (some c_e = 0: a zero on the
// diagonal of the lower-right block), or when that factorization refuses or
// its answer misses, use Eigen::SparseLU, LU with partial pivoting, on the
// matrix as written. Tell the cases apart from the matrix: S exactly
// symmetric, its lower-right block diagonal and < 0, its upper-left block
// with a positive diagonal that dominates each of its rows. Split the
// solution: the first velocity_unknowns entries are v_new, the rest λ.
// On a failed factorization (info()), a non-finite solution z, or one that
// misses the system, ‖Az − b‖∞ > 1e-8 (‖A‖∞‖z‖∞ + ‖b‖∞), return ok = false
// and a one-line problem (never NaN). Throw std::invalid_argument when the matrix
// is not square, the rhs has the wrong size, or velocity_unknowns is outside
// [0, size].
// Graded by tests/lab07_constrained_dynamics/test_spring.cpp (a 1-D spring in
// closed form, 1) and test_agreement.cpp (a dense solve on random scenes, 1);
// both hand you the KKT system the test writes out, not your kkt_system's.
StepSolution solve_kkt(const KktSystem& system, Eigen::Index velocity_unknowns) {
  (void)system, (void)velocity_unknowns;
  not_implemented("solve_kkt", __FILE__);
}

// TODO(lab07.4) [6 pts] The Schur-complement solve:
//     S = Δt² J W Jᵀ + C               (m × m; W = diag(step.inv_mass))
//     S λ = −φ − ΔtJ(v + Δt g)
//     v_new = v + Δt g + Δt W Jᵀ λ
// Factor S with cl::SpdFactorization; when factor() refuses, return ok = false
// with a problem line containing "singular". With no springs (m = 0) return
// v_new = v + Δt g and an empty λ. Check the step as kkt_system does.
// Graded by tests/lab07_constrained_dynamics/test_spring.cpp (a 1-D spring in
// closed form, 1), test_agreement.cpp (a dense solve of the KKT system on
// random scenes, 2), test_redundant.cpp (2) and test_update.cpp (no
// constraint, and the refusals, 1).
StepSolution solve_schur(const LinearizedStep& step) {
  (void)step;
  not_implemented("solve_schur", __FILE__);
}

// TODO(lab07.5) [4 pts] The update: v ← v_new for every movable particle
// (scatter `velocity` over map's unknowns), v = 0 for a pinned one, then
// x ← x + Δt v. Throw std::invalid_argument before changing anything when dt
// is not finite or ≤ 0 or the sizes disagree (velocity must have 3u entries).
// Graded by tests/lab07_constrained_dynamics/test_physics.cpp (C = 0 meets
// the linearised constraint, the hanging bead, the pendulum's period: 3) and
// test_update.cpp (the update alone: x moves by the new v, a pin's v is 0,
// refusals change nothing: 1).
void update_positions(Particles& particles, const MovableMap& map, const Eigen::VectorXd& velocity, double dt) {
  (void)particles, (void)map, (void)velocity, (void)dt;
  not_implemented("update_positions", __FILE__);
}

}  // namespace cl::lab07
