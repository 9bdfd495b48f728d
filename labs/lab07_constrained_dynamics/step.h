#pragma once
// Lab 07 — given code: one whole constrained step built from the student's
// pieces (constrained.h), and the optional post-step projection. Used by the
// driver, the graded tests, and later labs (08 compares its converged XPBD step
// with constrained_step; 09 adds geometric stiffness to the same pieces).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"
#include "common/sparse.h"
#include "constrained.h"

namespace cl::lab07 {

enum class Method { kKkt, kSchur };

struct StepSettings {
  double dt = 1.0 / 60.0;                    // s, finite and > 0
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  // m/s²
  Method method = Method::kSchur;
  // m/N added to the compliance of every HARD constraint (0: none). A way out
  // of a singular system (redundant hard constraints): it makes each of them a
  // very stiff spring of stiffness 1/regularization. Finite springs are unchanged.
  double regularization = 0.0;
};

// c_e = 1/k_e per spring (m/N), 0 for a hard one, plus `regularization` on the
// hard ones. EMPTY when every spring is hard and regularization is 0: a scene
// made only of hard constraints has no compliance block. Throws
// std::invalid_argument for a stiffness that is not > 0 or a regularization
// that is not finite or < 0.
Eigen::VectorXd compliance_of(const std::vector<Spring>& springs, double regularization = 0.0);

// The pieces of one step at the current state: φ and J (the student's
// constraint_values and constraint_jacobian), compliance_of(springs,
// settings.regularization), and W, v, g, Δt gathered over map's unknowns.
LinearizedStep linearize(const Particles& particles, const std::vector<Spring>& springs, const MovableMap& map,
                         const StepSettings& settings);

struct StepResult {
  bool ok = false;          // false: the particles were not changed (see problem)
  std::string problem;      // one line, when !ok
  Eigen::VectorXd lambda;   // λ per spring in file order, N (see constrained.h for the sign); empty when !ok
};

// One step: linearize, then kkt_system + solve_kkt (Method::kKkt) or
// solve_schur (Method::kSchur), then update_positions. When the solve fails
// (a singular system) the particles are left exactly as they were and the
// result says why. Throws std::invalid_argument for invalid settings or a
// state whose sizes disagree, and std::runtime_error with
// out_of_memory_problem's line when memory runs out (instead of a bare
// std::bad_alloc, which names neither the matrix nor a way out).
StepResult constrained_step(Particles& particles, const std::vector<Spring>& springs, const StepSettings& settings);

// The same with a map built once by the caller (make_movable_map of the
// particles' inverse masses), to save rebuilding it every step.
StepResult constrained_step(Particles& particles, const std::vector<Spring>& springs, const MovableMap& map,
                            const StepSettings& settings);

// Empty when `solution` is a usable solve with `unknowns` velocity entries and
// `constraints` multipliers; otherwise why not, in one line: the solve failed
// (its own problem, or "the solve failed without saying why"), or returned
// v_new or λ of the wrong size, or non-finite ones. Lab 09's step judges its
// solves with it too.
std::string solution_problem(const StepSolution& solution, Eigen::Index unknowns, Eigen::Index constraints);

// The line for a step whose memory ran out while it assembled or factored
// its system of `unknowns` velocity entries (3 per movable particle) and
// `constraints` rows: what ran out, the matrix of the method and its size,
// and what to try (a smaller scene; for the KKT solve, the Schur solve, whose
// matrix has one row per constraint only).
std::string out_of_memory_problem(Method method, Eigen::Index unknowns, Eigen::Index constraints);

// max_e |φ_e| (m), 0 without springs.
double max_constraint_error(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

// True when the rows of J for the hard constraints are dependent at the
// current positions (J_h W J_hᵀ is singular to working precision): the Schur
// solve at C = 0 refuses, and λ is not unique. False without hard constraints.
bool hard_constraints_redundant(const Particles& particles, const std::vector<Spring>& springs,
                                const MovableMap& map);

struct ProjectionResult {
  bool ok = true;             // false: the hard constraints' matrix was singular; nothing moved
  std::string problem;
  int hard_constraints = 0;   // how many constraints were projected
  double max_error_before = 0.0;  // max |φ_e| over the hard constraints, m
  double max_error_after = 0.0;
};

// Post-step stabilisation: ONE Gauss-Newton projection of the positions onto
// the hard constraints (stiffness "inf"), mass-weighted:
//     (J_h W J_hᵀ) μ = −φ_h,   x ← x + W J_hᵀ μ.
// Velocities are not changed. Springs of finite stiffness are not projected;
// with no hard constraint this is a no-op. Costs one more factorization and
// solve of the size of the Schur complement per step.
ProjectionResult stabilize_positions(Particles& particles, const std::vector<Spring>& springs,
                                     const MovableMap& map);

}  // namespace cl::lab07
