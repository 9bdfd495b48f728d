// Lab 13 — your code. Read constrained_newton.h (the contract) and README.md
// (the derivation) first. Grade with:  ./course grade lab13
#include "constrained_newton.h"

#include "common/not_implemented.h"
#include "constrained.h"

namespace cl::lab13 {

// TODO(lab13.1) [5 pts] The residuals at (x, λ): for each unknown k (particle
// p = map.particle_of[k]) inertia.segment<3>(3k) = (x_p − y_p) / (w_p Δt²);
// constraint_force = Jᵀλ with J = lab07::constraint_jacobian(x, springs, map);
// force = inertia − constraint_force; constraint = lab07::constraint_values(x,
// springs) + c ⊙ λ (no C term when compliance is empty). Check the sizes and
// dt first (std::invalid_argument).
// Graded by tests/lab13_constrained_newton/test_residuals.cpp.
Residuals residuals(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const Eigen::VectorXd& lambda,
                    const std::vector<Spring>& springs, const Eigen::VectorXd& inv_mass, const MovableMap& map,
                    const Eigen::VectorXd& compliance, double dt) {
  (void)x, (void)y, (void)lambda, (void)springs, (void)inv_mass, (void)map, (void)compliance, (void)dt;
  not_implemented("residuals", __FILE__);
}

// TODO(lab13.2) [7 pts] v̂ = (y − x)/Δt − Δt g for every unknown, stacked.
// Graded by tests/lab13_constrained_newton/test_rebased.cpp (at the start
// it is the velocity; the first iteration is lab 09's step; at any iterate
// lab 09's system is the Newton system).
Eigen::VectorXd rebased_velocity(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const MovableMap& map,
                                 const Eigen::Vector3d& gravity, double dt) {
  (void)x, (void)y, (void)map, (void)gravity, (void)dt;
  not_implemented("rebased_velocity", __FILE__);
}

// TODO(lab13.3) [3 pts] λ⁰: zeros for Warm::kZero; for Warm::kForces −k_e φ_e(x)
// on finite springs (φ from lab07::constraint_values, which also checks the
// springs), previous_lambda[e] on hard ones when it has one entry per spring.
// Graded by tests/lab13_constrained_newton/test_warm_start.cpp.
Eigen::VectorXd warm_start(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs,
                           const Eigen::VectorXd& previous_lambda, Warm warm) {
  (void)x, (void)springs, (void)previous_lambda, (void)warm;
  not_implemented("warm_start", __FILE__);
}

// TODO(lab13.4) [5 pts] force_error = ‖force‖∞ / max(‖inertia‖∞,
// ‖constraint_force‖∞) (0 when ‖force‖∞ = 0), constraint_error =
// ‖constraint‖∞ / length_scale, converged when both ≤ tolerance. A NaN or
// infinite residual gives an error that is not finite: never converged.
// Graded by tests/lab13_constrained_newton/test_convergence.cpp.
Convergence convergence(const Residuals& residuals, double length_scale, double tolerance) {
  (void)residuals, (void)length_scale, (void)tolerance;
  not_implemented("convergence", __FILE__);
}

// TODO(lab13.5) [2 pts] D_e = 1 / (c_e + Δt² (w_i + w_j)), 0 where that is 0.
// Graded by tests/lab13_constrained_newton/test_merit.cpp.
Eigen::VectorXd merit_weights(const std::vector<Spring>& springs, const Eigen::VectorXd& inv_mass,
                              const Eigen::VectorXd& compliance, double dt) {
  (void)springs, (void)inv_mass, (void)compliance, (void)dt;
  not_implemented("merit_weights", __FILE__);
}

// TODO(lab13.5) [2 pts] ψ = ½ Δt² Σ_k w_k force_k² + ½ Σ_e D_e constraint_e².
// Graded by tests/lab13_constrained_newton/test_merit.cpp.
double merit(const Residuals& residuals, const Eigen::VectorXd& inv_mass, const MovableMap& map,
             const Eigen::VectorXd& weights, double dt) {
  (void)residuals, (void)inv_mass, (void)map, (void)weights, (void)dt;
  not_implemented("merit", __FILE__);
}

// TODO(lab13.6) [2 pts] Accept ψ(α) ≤ (1 − 2 kArmijo α) ψ(0); never a
// non-finite ψ(α).
// Graded by tests/lab13_constrained_newton/test_merit.cpp.
bool sufficient_decrease(double merit_before, double merit_after, double alpha) {
  (void)merit_before, (void)merit_after, (void)alpha;
  not_implemented("sufficient_decrease", __FILE__);
}

}  // namespace cl::lab13
