#pragma once
// Lab 03 — many springs, Jacobi projection. The contract for the student's
// code. Derivation: labs/lab03_jacobi/README.md. Sources: Müller et al.,
// "Position Based Dynamics" (2007); Macklin et al., "Unified Particle Physics
// for Real-Time Applications" (2014), §4.2 (constraint averaging, relaxation ω).
//
// Units: positions in m, inverse masses in 1/kg (0 = pinned), lengths in m.
// Every spring is treated as a hard distance constraint (stiffness unused).
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"

namespace cl::lab03 {

// Which springs touch each particle (given code, built once per scene): the
// springs of particle p are spring[offset[p]] … spring[offset[p+1] − 1], in
// increasing spring index. offset has n + 1 entries, spring has 2m.
struct Incidence {
  std::vector<int> offset;
  std::vector<int> spring;
  int count(Eigen::Index p) const { return offset[static_cast<std::size_t>(p) + 1] - offset[static_cast<std::size_t>(p)]; }
};
Incidence build_incidence(Eigen::Index particle_count, const std::vector<Spring>& springs);

enum class Averaging {
  kNone,     // plain summed Jacobi: apply ω Σ Δx
  kByCount,  // averaged Jacobi: apply ω Σ Δx / (number of springs at the particle)
};

// TODO(lab03.1) — one Jacobi sweep.
//
// Every spring's correction is computed from the SAME positions x (the start
// of the sweep) with lab01's project_distance. For each particle p:
//     Δ_p = Σ over springs s touching p of s's correction for p
//     x_next_p = x_p + ω Δ_p / c_p
// with c_p = incidence.count(p) for Averaging::kByCount and c_p = 1 for
// Averaging::kNone. A particle touched by no spring keeps its position.
//
// Gather, do not scatter: compute x_next_p particle by particle, walking p's
// springs in incidence order, so the sum is added in the same order whatever
// the thread count. Parallelise the loop over particles with OpenMP
// (`#pragma omp parallel for`): with the gather, 1 and 2 threads give the
// same bits. (Each spring is projected once from each end.)
//
// Shapes: x is 3 × n; x_next is resized to 3 × n and overwritten (it must not
// alias x); inv_mass has n entries; incidence built from the same springs.
// ω = 0 leaves x unchanged. Throws std::invalid_argument for mismatched shapes,
// a negative or non-finite ω, inverse mass or rest length — checked BEFORE the
// parallel loop, because an exception may not leave an OpenMP region.
void jacobi_sweep(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& x_next, const Eigen::VectorXd& inv_mass,
                  const std::vector<Spring>& springs, const Incidence& incidence, double omega,
                  Averaging averaging);

}  // namespace cl::lab03
