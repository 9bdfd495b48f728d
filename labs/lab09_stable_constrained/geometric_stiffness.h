#pragma once
// Lab 09 — stable constrained dynamics: lab 07's step with the geometric
// stiffness of the distance constraints put back. The contract for the
// student's code. Derivation: labs/lab09_stable_constrained/README.md. Source:
// Tournier, Nesme, Gilles and Faure, "Stable Constrained Dynamics" (ACM
// Transactions on Graphics 34(4), 2015): the geometric stiffness in the KKT system.
//
// Units: positions in m, velocities in m/s, inverse masses in 1/kg (0 =
// pinned), time in s, compliance in m/N, multipliers λ in N, stiffness
// matrices in N/m.
//
// Notation and sign convention: lab 07's (constrained.h). The force the
// constraints put on the particles is Jᵀλ; λ_e < 0 is tension (a stretched
// spring), λ_e > 0 compression. A spring of stiffness k has energy ½kφ², force
// −Jᵀkφ, so its force is Jᵀλ with λ = −kφ = −C⁻¹φ.
//
// Geometric stiffness. J depends on x, so the constraint force changes with
// the positions even at fixed λ:
//     K_g = ∂(Jᵀλ)/∂x  (λ held fixed),  3u × 3u, symmetric.
// For spring e with d = x_i − x_j, ℓ = ‖d‖, n = d/ℓ, its block is
//     B_e = λ_e (I − n nᵀ) / ℓ   (3 × 3)
// added as +B_e at (i, i) and (j, j), −B_e at (i, j) and (j, i).
// With that sign, the Hessian of the springs' energy is H = Jᵀ C⁻¹ J − K_g
// (with λ = −C⁻¹φ), and implicit Euler's matrix is M + Δt² H.
//
// The step with K_g (λ̄ = the multipliers K_g is built from, see stable_step.h):
//   [ M − Δt² K_g   −ΔtJᵀ ] [ v_new ]   [ M(v + Δt g) ]
//   [ ΔtJ             C   ] [ λ     ] = [ −φ          ]
// then x ← x + Δt v_new. With K_g = 0 this is lab 07's system exactly.
//
// Compression. A block of a compressed constraint (λ_e > 0) is positive
// semidefinite, so −Δt² K_g can make M − Δt² K_g indefinite: the Schur solves
// below then have no SPD matrix to factor, and the physics (buckling) is not
// what a time step should decide. The treatment used by the step: drop the
// compressed constraints from K_g (use min(λ_e, 0) in place of λ_e,
// Compression::kDrop). Then −K_g is positive semidefinite and M − Δt² K_g is
// SPD whatever λ is. Compression::kKeep is the exact derivative (for the
// finite-difference test, and to see the refusal).
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/sparse.h"
#include "constrained.h"

namespace cl::lab09 {

enum class Compression {
  kDrop,  // only tension (λ_e < 0) contributes: −K_g is positive semidefinite
  kKeep,  // every λ_e as given: the exact ∂(Jᵀλ)/∂x, possibly indefinite
};

// TODO(lab09.1) — the geometric stiffness K_g = ∂(Jᵀλ)/∂x at fixed λ, over
// map's movable unknowns: 3u × 3u, symmetric, the ±B_e block pattern above
// (a pinned end's rows and columns are dropped, as in lab 07's Jacobian).
// x is 3 × n, lambda has one entry per spring (N, lab 07's sign). With
// Compression::kDrop a spring with λ_e > 0 contributes nothing. Coincident
// ends (ℓ = 0) have no direction: the spring contributes nothing (documented
// no-op, never NaN). The rest length is not used. Throws std::invalid_argument
// for an index out of range, i == j, a map without one entry per particle, or
// lambda of the wrong size or not finite.
SparseMatrix geometric_stiffness(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs,
                                 const Eigen::VectorXd& lambda, const MovableMap& map,
                                 Compression compression);

// TODO(lab09.2) — lab 07's KKT system (lab07::kkt_system) with the upper-left
// block M replaced by M − Δt² K_g; the right-hand side is unchanged. Solve it
// with lab07::solve_kkt. Throws std::invalid_argument like lab07::kkt_system,
// and when geometric_stiffness is not 3u × 3u.
lab07::KktSystem stiff_kkt_system(const lab07::LinearizedStep& step, const SparseMatrix& geometric_stiffness);

// The primal Schur complement: λ eliminated, v_new the only unknown.
struct EliminatedSystem {
  SparseMatrix matrix;   // 3u × 3u
  Eigen::VectorXd rhs;   // 3u entries
};

// TODO(lab09.3) — eliminate λ = −C⁻¹(φ + ΔtJ v_new) from the system above
// (possible only when every constraint is compliant, c_e > 0):
//     (M − Δt² K_g + Δt² Jᵀ C⁻¹ J) v_new = M(v + Δt g) − Δt Jᵀ C⁻¹ φ.
// With K_g built from λ = −C⁻¹φ (Compression::kKeep) this is exactly
// implicit Euler's (M + Δt² H) v_new = M(v + Δt g) + Δt f(x) for the same
// springs. Throws std::invalid_argument like stiff_kkt_system, and when
// step.compliance is empty while there are springs (m > 0: every constraint
// hard) or has an entry that is not > 0 (a hard constraint cannot be
// eliminated this way: see solve_stiff_schur). With no springs there is
// nothing to eliminate: the system is M − Δt² K_g, M(v + Δt g).
EliminatedSystem eliminated_system(const lab07::LinearizedStep& step, const SparseMatrix& geometric_stiffness);

// TODO(lab09.4) — the Schur-complement solve of the system above, with
// cl::SpdFactorization:
//  * every constraint compliant (c_e > 0 for all e): factor
//    eliminated_system's matrix, solve for v_new, then λ = −C⁻¹(φ + ΔtJ v_new);
//  * otherwise (some c_e = 0, or step.compliance empty): lab 07's dual form
//    with M̃ = M − Δt² K_g in place of M. Factor M̃, then
//        (Δt² J M̃⁻¹ Jᵀ + C) λ = −φ − ΔtJ M̃⁻¹ M(v + Δt g),
//        v_new = M̃⁻¹ (M(v + Δt g) + ΔtJᵀλ).
//    The m × m matrix is dense in general (M̃⁻¹ couples everything): this
//    branch costs O(m·3u) memory and is meant for small scenes; use the KKT
//    solve for large ones.
// With no springs, v_new = v + Δt g. With K_g = 0 both branches give lab 07's
// solve_schur to round-off. When a factorization refuses, returns ok = false
// (never NaN) with a problem line that says "not positive definite" (M̃ or
// the eliminated matrix: compressed constraints kept with a large λ) or
// "singular" (the dual matrix: redundant hard constraints). Throws
// std::invalid_argument like stiff_kkt_system.
lab07::StepSolution solve_stiff_schur(const lab07::LinearizedStep& step, const SparseMatrix& geometric_stiffness);

}  // namespace cl::lab09
