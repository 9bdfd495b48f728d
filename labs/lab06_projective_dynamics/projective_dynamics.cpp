// Lab 06 — your code. Read projective_dynamics.h (the contract) and README.md
// (the derivation) first. Grade with:  ./course grade lab06
//
// The five functions below make one projective dynamics iteration; the given
// code (simulation.cpp) runs them K times per step. Besides the tests named
// in each block, tests/lab06_projective_dynamics/test_step.cpp,
// test_oscillator.cpp and test_stability.cpp (8 pts) run whole steps and need
// all five.
#include "projective_dynamics.h"

#include "common/not_implemented.h"

namespace cl::lab06 {

// TODO(lab06.1) [2 pts] The local step.
// For each spring e = (i, j) with rest length L_e, the point of the sphere of
// radius L_e nearest to x_i − x_j:  d_e = L_e (x_i − x_j) / ‖x_i − x_j‖.
// If the computed ‖x_i − x_j‖ (.norm()) is 0 — equal ends, or ends closer
// than about 1e-162 m, whose squared length underflows — return
// d_e = L_e (1, 0, 0) (every direction is equally near; this one is documented). Throw std::invalid_argument for an index
// outside the columns of x. Returns 3 × m, column e for springs[e].
// Graded by tests/lab06_projective_dynamics/test_local_step.cpp (2 pts).
Eigen::Matrix3Xd local_step(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  (void)x, (void)springs;
  not_implemented("local_step", __FILE__);
}

// TODO(lab06.2) [2 pts] The global matrix A = M/Δt² + Σ_e k_e S_eᵀ S_e over the unknowns.
// Check dt (finite, > 0) and each stiffness (finite, > 0; name the spring in
// the message); throw std::invalid_argument otherwise. Collect triplets: for
// each unknown u (particle problem.map.particle_of[u]) m/Δt² at (u, u); for
// each spring with unknowns a = map.unknown_of[i], b = map.unknown_of[j]
// (−1 = pinned): +k at (a, a) if a >= 0, +k at (b, b) if b >= 0, and −k at
// (a, b) and (b, a) if both are. Return cl::assemble(n_u, n_u, triplets).
// Graded by tests/lab06_projective_dynamics/test_system_matrix.cpp (2 pts).
SparseMatrix system_matrix(const Problem& problem) {
  (void)problem;
  not_implemented("system_matrix", __FILE__);
}

// TODO(lab06.3) [with lab06.4: 2 pts] The right-hand side b (n_u × 3).
// Row u starts at m/Δt² · y_p. Then each spring (i, j) adds +k·d_e to the row
// of i if i is movable and −k·d_e to the row of j if j is movable — whether or
// not the other end is pinned — and, for a pinned end, its held position k·y
// (the pinned particle's column of y) to the movable end's row: in all,
// b_i += k(y_j + d_e) for a pinned j, b_j += k(y_i − d_e) for a pinned i
// (see the header).
// Check the columns of y (n) and d (m); throw std::invalid_argument otherwise.
// Graded by tests/lab06_projective_dynamics/test_global_step.cpp.
RowsX3 right_hand_side(const Problem& problem, const Eigen::Matrix3Xd& y, const Eigen::Matrix3Xd& d) {
  (void)problem, (void)y, (void)d;
  not_implemented("right_hand_side", __FILE__);
}

// TODO(lab06.4) [with lab06.3: 2 pts] The global step.
// Throw std::invalid_argument unless factor.ok() and factor.size() is n_u.
// b = right_hand_side(...); solve all three coordinates at once with
// factor.solve3(b); return y with the movable columns replaced by the
// solution (cl::scatter_rows).
// Graded by tests/lab06_projective_dynamics/test_global_step.cpp.
Eigen::Matrix3Xd global_step(const Problem& problem, const SpdFactorization& factor, const Eigen::Matrix3Xd& y,
                             const Eigen::Matrix3Xd& d) {
  (void)problem, (void)factor, (void)y, (void)d;
  not_implemented("global_step", __FILE__);
}

// TODO(lab06.5) [1 pt] The objective g(x) = Σ_movable m‖x − y‖²/(2Δt²) + Σ_e k_e/2 (‖x_i − x_j‖ − L_e)².
// Check the columns of x and y (n); throw std::invalid_argument otherwise.
// Graded by tests/lab06_projective_dynamics/test_global_step.cpp (1 pt).
double objective(const Problem& problem, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y) {
  (void)problem, (void)x, (void)y;
  not_implemented("objective", __FILE__);
}

}  // namespace cl::lab06
