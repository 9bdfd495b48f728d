// Lab 09 — your code. Read geometric_stiffness.h (the contract) and README.md
// (the derivation) first. Grade with:  ./course grade lab09
#include "geometric_stiffness.h"

#include "common/not_implemented.h"

namespace cl::lab09 {

// TODO(lab09.1) [5 pts] The geometric stiffness K_g = ∂(Jᵀλ)/∂x at fixed λ,
// 3u × 3u over map's unknowns. For spring e with d = x_i − x_j, ℓ = ‖d‖,
// n = d/ℓ and force f = λ_e (f = min(λ_e, 0) with Compression::kDrop):
//     B_e = f (I − n nᵀ) / ℓ,
// +B_e into the (i, i) and (j, j) blocks, −B_e into (i, j) and (j, i), block
// (a, b) being rows 3·unknown_of[a] + r, columns 3·unknown_of[b] + c. Skip a
// pinned end (unknown_of = −1) and a spring with ℓ = 0. Collect cl::Triplet
// entries and call cl::assemble(3u, 3u, triplets). Throw std::invalid_argument
// for an index out of range, i == j, a map of the wrong size, or lambda of the
// wrong size or not finite.
// Graded by tests/lab09_stable_constrained/test_geometric_stiffness.cpp:
// central differences of Jᵀλ to 1e-6 (3), the compression treatment (2).
SparseMatrix geometric_stiffness(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs,
                                 const Eigen::VectorXd& lambda, const MovableMap& map,
                                 Compression compression) {
  (void)x, (void)springs, (void)lambda, (void)map, (void)compression;
  not_implemented("geometric_stiffness", __FILE__);
}

// TODO(lab09.2) [2 pts] Lab 07's KKT system with M − Δt² K_g in its upper-left
// 3u × 3u block: build lab07::kkt_system(step), then add −Δt²·K_g's entries
// (as triplets at the same rows and columns, assembled to the KKT matrix's
// size). Check that geometric_stiffness is 3u × 3u (std::invalid_argument).
// Graded by tests/lab09_stable_constrained/test_solves.cpp.
lab07::KktSystem stiff_kkt_system(const lab07::LinearizedStep& step, const SparseMatrix& geometric_stiffness) {
  (void)step, (void)geometric_stiffness;
  not_implemented("stiff_kkt_system", __FILE__);
}

// TODO(lab09.3) [3 pts] Eliminate λ (every c_e > 0):
//     A = M − Δt² K_g + Δt² Jᵀ C⁻¹ J,      b = M(v + Δt g) − Δt Jᵀ C⁻¹ φ,
// M = diag(1/step.inv_mass). Throw std::invalid_argument when compliance is
// empty while there are springs (m > 0) or has an entry that is not > 0, when sizes disagree,
// and for dt or inverse masses as lab07::kkt_system does.
// Graded by tests/lab09_stable_constrained/test_eliminated.cpp: A equals
// implicit Euler's M + Δt² H, b its right-hand side.
EliminatedSystem eliminated_system(const lab07::LinearizedStep& step, const SparseMatrix& geometric_stiffness) {
  (void)step, (void)geometric_stiffness;
  not_implemented("eliminated_system", __FILE__);
}

// TODO(lab09.4) [3 pts] The Schur solve with K_g, factoring with
// cl::SpdFactorization (factor() returns false when a matrix is not SPD):
//  * all c_e > 0: A v_new = b (eliminated_system), λ = −(φ + ΔtJ v_new)/c_e;
//  * else: M̃ = M − Δt² K_g; S = Δt² J M̃⁻¹ Jᵀ + C (dense: solve M̃ Y = Jᵀ
//    for all columns at once, e.g. factor.eigen().solve(Eigen::MatrixXd(Jᵀ)));
//    S λ = −φ − ΔtJ M̃⁻¹ M(v + Δt g);  v_new = M̃⁻¹(M(v + Δt g) + ΔtJᵀλ).
// A refused factorization: ok = false and a problem line containing "not
// positive definite" (A or M̃) or "singular" (S). No springs: v_new = v + Δt g.
// Graded by tests/lab09_stable_constrained/test_solves.cpp (agreement with the
// KKT solve and with lab 07 at K_g = 0: 2; the refusal: 1). The whole step,
// all four functions through the given stable_step, is graded by
// test_heavy_chain.cpp (3 more points).
lab07::StepSolution solve_stiff_schur(const lab07::LinearizedStep& step, const SparseMatrix& geometric_stiffness) {
  (void)step, (void)geometric_stiffness;
  not_implemented("solve_stiff_schur", __FILE__);
}

}  // namespace cl::lab09
