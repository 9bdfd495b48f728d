#pragma once
// Lab 04 — position based dynamics. The contract for the student's code.
// Derivation: labs/lab04_pbd/README.md. Source: Müller et al., "Position Based
// Dynamics" (2007), §3.1 (the algorithm), §3.5 (velocity update).
//
// Units: positions in m, velocities in m/s, inverse masses in 1/kg (0 =
// pinned), time in s, gravity in m/s².
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"
#include "jacobi.h"

namespace cl::lab04 {

enum class Projection { kGaussSeidel, kJacobi };

struct PbdSettings {
  double dt = 1.0 / 60.0;                          // step, s, > 0
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};        // m/s²
  int iterations = 10;                             // K sweeps per step, >= 0
  Projection projection = Projection::kGaussSeidel;
  double omega = 1.0;                              // Jacobi relaxation (lab 03)
};

// The springs and what the two sweeps need about them, built once per scene
// (given code: make_constraint_set, in constraint_set.cpp).
struct ConstraintSet {
  std::vector<Spring> springs;
  std::vector<int> order;      // Gauss-Seidel order (file order: 0 … m−1)
  lab03::Incidence incidence;  // for Jacobi
};
ConstraintSet make_constraint_set(Eigen::Index particle_count, std::vector<Spring> springs);

// TODO(lab04.1) — one PBD step of size dt.
//
// For each movable particle (inverse mass > 0):
//     v ← v + Δt g                       (external force: gravity)
//     p ← x + Δt v                       (predicted position)
// Pinned particles (inverse mass 0) keep their position: p = x, v = 0.
// Then K = settings.iterations sweeps on p — lab02's gauss_seidel_sweep in
// constraints.order, or lab03's averaged jacobi_sweep with ω — and finally
//     v ← (p − x) / Δt,   x ← p.
// With no springs this is symplectic Euler: x_n = x_0 + nΔt v_0 + Δt² g n(n+1)/2.
//
// Every spring is a hard distance constraint here (its stiffness is not used):
// how stiff the result is depends on K, Δt and the mesh (README.md).
//
// Shapes: particles.x and .v are 3 × n, updated in place; inv_mass has n
// entries. Throws std::invalid_argument, before changing anything, for dt that
// is not finite or ≤ 0, iterations < 0, or v / inv_mass not sized for n
// particles; the sweeps throw for invalid springs or ω as labs 02 and 03 say.
void pbd_step(Particles& particles, const ConstraintSet& constraints, const PbdSettings& settings);

}  // namespace cl::lab04
