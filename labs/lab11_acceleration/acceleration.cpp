// Lab 11 — your code. Read acceleration.h (the contract) and README.md (the
// derivations) first. Grade with:  ./course grade lab11
//
// The five functions below are the pieces of the accelerated loops; the given
// code (accelerated.cpp) runs them. Besides the tests named in each block,
// the Chebyshev-bound case of tests/lab11_acceleration/test_update.cpp (2 pts)
// needs lab11.1 and lab11.2, and test_loops.cpp (9 pts) runs whole
// accelerated steps and needs all five.
#include "acceleration.h"

#include "common/not_implemented.h"

namespace cl::lab11 {

// TODO(lab11.1) [2 pts] The Chebyshev weight of the j-th accelerated iteration.
// j = 1: 1; j = 2: 2/(2 − ρ²); j ≥ 3: 4/(4 − ρ² · previous_omega). Check j >= 1,
// ρ finite in [0, 1) and, for j >= 3, previous_omega finite in [1, 2); throw
// std::invalid_argument with the offending value otherwise.
// Graded by tests/lab11_acceleration/test_weights.cpp (2 pts).
double chebyshev_weight(int j, double rho, double previous_omega) {
  (void)j, (void)rho, (void)previous_omega;
  not_implemented("chebyshev_weight", __FILE__);
}

// TODO(lab11.2) [2 pts] The accelerated update
//     q_next = ω γ q_hat + ω (1 − γ) q + (1 − ω) q_previous
// (the expanded form of ω (γ (q_hat − q) + q − q_previous) + q_previous).
// Check the three shapes agree, ω finite in [1, 2), γ finite in (0, 2).
// Graded by the first case of tests/lab11_acceleration/test_update.cpp (2 pts).
Eigen::Matrix3Xd chebyshev_update(const Eigen::Matrix3Xd& q_hat, const Eigen::Matrix3Xd& q,
                                  const Eigen::Matrix3Xd& q_previous, double omega, double gamma) {
  (void)q_hat, (void)q, (void)q_previous, (void)omega, (void)gamma;
  not_implemented("chebyshev_update", __FILE__);
}

// TODO(lab11.3) [2 pts] ρ from the update lengths of a plain run: with n
// lengths and w = n / 2 (integer division), (e[n−1] / e[n−1−w])^(1/w). Return 0
// when either of the two is 0; throw for n < 2 or a negative or non-finite length.
// Graded by tests/lab11_acceleration/test_estimate.cpp (2 pts).
double estimate_spectral_radius(const std::vector<double>& update_norms) {
  (void)update_norms;
  not_implemented("estimate_spectral_radius", __FILE__);
}

// TODO(lab11.4) [1 pt] The restart rule: true when objective_after is not
// finite or exceeds objective_before + slack · |objective_before|.
// Throw for a non-finite objective_before, or a slack that is negative or not finite.
// Graded by tests/lab11_acceleration/test_restart.cpp (1 pt).
bool restart_needed(double objective_before, double objective_after, double slack) {
  (void)objective_before, (void)objective_after, (void)slack;
  not_implemented("restart_needed", __FILE__);
}

// TODO(lab11.5) [4 pts] The L-BFGS two-loop recursion with initial_inverse as
// H₀, applied as given (see the header for the two loops). Skip every pair
// whose sᵀy is not > 0 in both loops; return d = −H ∇g. Throw when a pair's
// size differs from the gradient's.
// Graded by tests/lab11_acceleration/test_lbfgs.cpp (4 pts: the dense update,
// then one case each for H₀ unscaled, the skip, and the loops' order).
Eigen::VectorXd lbfgs_direction(const Eigen::VectorXd& gradient, const std::vector<CurvaturePair>& pairs,
                                const InverseApply& initial_inverse) {
  (void)gradient, (void)pairs, (void)initial_inverse;
  not_implemented("lbfgs_direction", __FILE__);
}

}  // namespace cl::lab11
