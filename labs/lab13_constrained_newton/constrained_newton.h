#pragma once
// Lab 13 — constrained Newton: the compliant implicit-Euler step solved by
// Newton's method on the constrained (primal-dual) system, with the
// multipliers λ kept as unknowns. The contract for the student's code.
// Derivation: labs/lab13_constrained_newton/README.md. Sources: Tournier,
// Nesme, Gilles and Faure, "Stable Constrained Dynamics" (2015: the first
// iteration is their step, lab 09); Goldenthal, Harmon, Fattal, Bercovier and
// Grinspun, "Efficient Simulation of Inextensible Cloth" (2007: the same
// linearised solve iterated for C = 0, "fast projection"); Macklin, Müller and
// Chentanez, "XPBD" (2016: the compliant residual φ + α̃λ) and Macklin et al.,
// "Primal/Dual Descent Methods for Dynamics" (2020: the primal/dual choice).
//
// Units: positions in m, inverse masses in 1/kg (0 = pinned), time in s,
// compliance in m/N (c_e = 1/k_e, 0 for a hard spring), multipliers λ in N
// (lab 07's sign: λ_e < 0 is tension), forces in N.
//
// Notation: lab 07's (constrained.h). n particles, u of them movable (the
// unknowns, common/sparse.h: MovableMap), m springs in file order; "stacked"
// vectors have 3u entries, unknown k's (x, y, z) at 3k, 3k+1, 3k+2. y is the
// prediction x_old + Δt v + Δt² g (lab06::predict; y = x for pinned
// particles), M = diag(1/inv_mass) over the unknowns.
//
// The step. The compliant implicit-Euler step is the (x, λ) with
//     r_x = M(x − y)/Δt² − J(x)ᵀλ = 0      (3u entries, N)
//     r_λ = φ(x) + Cλ            = 0      (m entries, m)
// For C > 0 its x is lab 06's minimiser of g (λ = −C⁻¹φ); for C = 0 it is the
// M-norm projection of y onto the constraint manifold φ = 0 (the hard step).
// One Newton iteration at (x_k, λ_k) solves
//     [ M/Δt² − K_g(λ_k)   −Jᵀ ] [ Δx    ]   [ M(y − x_k)/Δt² ]
//     [ J                   C  ] [ λ_new ] = [ −φ(x_k)        ]
// (J, φ at x_k; K_g lab 09's geometric stiffness). Times Δt in the first row
// and with Δx = Δt v̂_new this is lab 09's system at x_k for the velocity
// v̂ = rebased_velocity(x_k, y, ...): the given code solves it with lab 09's
// solves, never a copy of them.
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/sparse.h"

namespace cl::lab13 {

// The residuals at one iterate, and the two terms r_x balances.
struct Residuals {
  Eigen::VectorXd inertia;           // M(x − y)/Δt², stacked, 3u entries, N
  Eigen::VectorXd constraint_force;  // J(x)ᵀλ, stacked, 3u entries, N
  Eigen::VectorXd force;             // r_x = inertia − constraint_force, 3u entries, N
  Eigen::VectorXd constraint;        // r_λ = φ(x) + Cλ, m entries, m
};

// TODO(lab13.1) — the residuals above at (x, λ). x, y: 3 × n; lambda: m
// entries (N); inv_mass: n entries (1/kg, per particle; 0 = pinned, no row);
// compliance: lab 07's (m entries, 0 for a hard spring, or EMPTY when every
// spring is hard: C = 0). φ and J are lab 07's constraint_values and
// constraint_jacobian (coincident ends: an empty row of J, never NaN).
// Throws std::invalid_argument when x, y, inv_mass or map do not have one
// entry per particle, lambda does not have one per spring, compliance is
// neither empty nor one per spring, or a dt that is NaN, infinite or ≤ 0.
Residuals residuals(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const Eigen::VectorXd& lambda,
                    const std::vector<Spring>& springs, const Eigen::VectorXd& inv_mass, const MovableMap& map,
                    const Eigen::VectorXd& compliance, double dt);

// TODO(lab13.2) — the velocity v̂ that re-bases lab 09's right-hand side at
// the iterate x (stacked over map's unknowns, m/s):
//     v̂ = (y − x)/Δt − Δt g,   so that   M(v̂ + Δt g) = M(y − x)/Δt,
// the Newton right-hand side's first row times Δt. At x = x_old it is the
// particles' own velocity, and the iteration's first step is lab 09's step.
// Throws std::invalid_argument when x, y or map disagree in size, or for a
// dt that is NaN, infinite or ≤ 0.
Eigen::VectorXd rebased_velocity(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const MovableMap& map,
                                 const Eigen::Vector3d& gravity, double dt);

// Where the multipliers start.
enum class Warm {
  kForces,  // the forces the springs carry at the start (below)
  kZero,    // λ⁰ = 0: the iteration must find every force itself
};

// TODO(lab13.3) — λ⁰, one entry per spring (N). Warm::kZero: 0. Warm::kForces:
// for a spring of finite stiffness k_e the force it carries at x,
//     λ⁰_e = −k_e φ_e(x)    (tension < 0, lab 07's sign);
// for a hard spring (k_e = inf) the previous step's multiplier
// previous_lambda[e] when previous_lambda has one entry per spring, else 0.
// Throws std::invalid_argument for x or a spring that lab 07's
// constraint_values refuses, or a previous_lambda that is not empty, not one
// per spring, or not finite.
Eigen::VectorXd warm_start(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs,
                           const Eigen::VectorXd& previous_lambda, Warm warm);

// How far an iterate is from the step, in two dimensionless numbers.
struct Convergence {
  // ‖r_x‖∞ / max(‖inertia‖∞, ‖constraint_force‖∞): the force imbalance
  // relative to the larger of the two forces it balances; 0 when r_x = 0
  // (also when both forces are 0).
  double force_error = 0.0;
  // ‖r_λ‖∞ / length_scale: for C = 0 the distance to the constraint
  // manifold, max |φ_e|, in units of the length scale.
  double constraint_error = 0.0;
  bool converged = false;  // both ≤ tolerance
  // A residual with a NaN or infinite entry gives a force or constraint error
  // that is not finite, and is never converged (NaN ≤ tolerance is false: no
  // guard may turn it into 0 on the way).
};

// TODO(lab13.4) — the convergence test above. length_scale (m, > 0): the
// given code passes the springs' mean rest length (iteration.h). With no
// unknowns the force error is 0; with no springs the constraint error is 0.
// Throws std::invalid_argument for a length_scale that is NaN, infinite or
// ≤ 0, a tolerance that is NaN, infinite or < 0, or residuals whose force,
// inertia and constraint_force sizes disagree.
Convergence convergence(const Residuals& residuals, double length_scale, double tolerance);

// TODO(lab13.5) — the merit's weights per spring (N/m):
//     D_e = 1 / (c_e + Δt² (w_i + w_j)),
// with w the inverse masses (a pinned end has w = 0) and c_e = compliance[e]
// (0 for every spring when compliance is empty). A spring whose denominator
// is 0 (hard, both ends pinned: nothing can change its φ) gets D_e = 0.
// Throws std::invalid_argument for sizes that disagree, a dt that is NaN,
// infinite or ≤ 0, or a spring index out of range.
Eigen::VectorXd merit_weights(const std::vector<Spring>& springs, const Eigen::VectorXd& inv_mass,
                              const Eigen::VectorXd& compliance, double dt);

// TODO(lab13.5) — the merit (J), the weighted squared residual
//     ψ = ½ Δt² Σ_k w_k r_x,k²  +  ½ Σ_e D_e r_λ,e²,
// w_k the inverse mass of the unknown that stacked entry k belongs to
// (map.particle_of[k / 3]). ψ ≥ 0, and 0 exactly at the step. Each term is
// an energy: Δt² w r_x² is (s²/kg) N² = J, D r_λ² is (N/m) m² = J. Throws
// std::invalid_argument for sizes that disagree or a dt that is NaN, infinite
// or ≤ 0.
double merit(const Residuals& residuals, const Eigen::VectorXd& inv_mass, const MovableMap& map,
             const Eigen::VectorXd& weights, double dt);

// TODO(lab13.6) — the safeguard's rule (Armijo on the merit). Along an exact
// Newton direction ψ'(0) = −2ψ(0), so a step of length α is accepted when
//     ψ(α) ≤ (1 − 2 σ α) ψ(0),   σ = kArmijo = 1e-4.
// A non-finite ψ(α) is never accepted. Throws std::invalid_argument for α not
// in (0, 1] or a merit_before that is negative or not finite.
inline constexpr double kArmijo = 1e-4;
bool sufficient_decrease(double merit_before, double merit_after, double alpha);

}  // namespace cl::lab13
