#pragma once
// Lab 09 — given code: one constrained step with geometric stiffness, built
// from lab 07's pieces (linearize, solve_kkt, update_positions) and the
// student's (geometric_stiffness.h); the heavy chain the tests and the
// stability experiment use; the transverse speed they measure.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"
#include "common/scene.h"
#include "common/sparse.h"
#include "geometric_stiffness.h"
#include "step.h"

namespace cl::lab09 {

struct StableSettings {
  lab07::StepSettings step;          // dt, gravity, method (KKT or Schur), regularization
  bool geometric_stiffness = true;   // false: K_g = 0, lab 07's step through the same solves
  Compression compression = Compression::kDrop;
};

struct StableStepResult {
  bool ok = false;           // false: the particles were not changed (see problem)
  std::string problem;       // one line, when !ok
  Eigen::VectorXd lambda;    // this step's λ per spring, N, lab 07's sign; empty when !ok
  bool first_solve = false;  // K_g's λ̄ came from a first solve without K_g (no previous λ)
};

// The system with K_g = stiffness solved by `method`: stiff_kkt_system and
// lab07::solve_kkt (Method::kKkt), or solve_stiff_schur (Method::kSchur).
// Lab 13 solves each of its Newton iterations with it.
lab07::StepSolution solve_stiff(const lab07::LinearizedStep& step, const SparseMatrix& stiffness,
                                lab07::Method method);

// One step of size settings.step.dt. K_g is built from λ̄ = previous_lambda,
// the multipliers of the previous step (pass the last result's lambda). When
// previous_lambda does not have one entry per spring (the first step), λ̄ comes
// from a first solve of the same step without K_g, whose velocities are
// discarded. Then K_g = geometric_stiffness(x, springs, λ̄, map, compression)
// and the step solves stiff_kkt_system + lab07::solve_kkt (Method::kKkt) or
// solve_stiff_schur (Method::kSchur), and moves the particles with
// lab07::update_positions. With geometric_stiffness off, K_g = 0 (an empty
// 3u × 3u matrix) in the same solves: lab 07's step. When a solve fails the
// particles are left as they were and the result says why. Throws
// std::invalid_argument for invalid settings or a state whose sizes disagree.
StableStepResult stable_step(Particles& particles, const std::vector<Spring>& springs, const MovableMap& map,
                             const StableSettings& settings, const Eigen::VectorXd& previous_lambda);

// The fastest a constraint turns: max over springs of ‖(I − n nᵀ)(v_i − v_j)‖,
// n = (x_i − x_j)/‖x_i − x_j‖, the relative velocity of the ends across the
// spring (m/s). 0 without springs; coincident ends are skipped.
double max_transverse_speed(const Particles& particles, const std::vector<Spring>& springs);

// ½ Σ k φ² over the springs of finite stiffness (J).
double spring_energy(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

// A heavy chain: `links` links of `link_length` m hanging straight down (−y)
// from a pinned particle at the origin, `links` − 1 beads of `bead_mass` kg
// and, at the bottom, a mass of mass_ratio × bead_mass. The links are hard
// (stiffness "inf") or springs of `stiffness` N/m whose rest length is
// link_length, stretched to hang at rest under the static tension. Every
// bead starts with a sideways (x) velocity of ±kick m/s, alternating in sign;
// the bottom mass starts at rest. Gravity [0, −9.81, 0], dt 1/60 s.
// Throws std::invalid_argument for links < 2 or a non-positive length, mass,
// ratio or stiffness, or a negative kick.
Scene heavy_chain(int links, double link_length, double bead_mass, double mass_ratio, double stiffness,
                  double kick);

}  // namespace cl::lab09
