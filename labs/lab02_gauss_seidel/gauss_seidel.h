#pragma once
// Lab 02 — many springs, Gauss-Seidel projection. The contract for the
// student's code. Derivation: labs/lab02_gauss_seidel/README.md. Source:
// Müller et al., "Position Based Dynamics" (2007), §3.2 (the solver loop).
//
// Units: positions in m, inverse masses in 1/kg (0 = pinned), lengths in m.
// Every spring is treated as a hard distance constraint ‖x_i − x_j‖ = rest;
// its stiffness is not used here (lab 08, XPBD, gives it a meaning).
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"

namespace cl::lab02 {

// TODO(lab02.1) — one Gauss-Seidel sweep.
//
// For s in `order` (spring indices, in that order): project springs[s] with
// lab01's project_distance using the CURRENT positions, and apply both
// corrections to x at once, so the next spring already sees them:
//     x_i += Δx_i,  x_j += Δx_j.
//
// Shapes: x is 3 × n (updated in place); inv_mass has n entries; `order` may
// list any spring indices (normally a permutation of 0 … m−1). An empty order
// is a no-op. Degenerate springs (both ends pinned, coincident ends) are the
// no-ops lab01 defines. Throws std::invalid_argument when inv_mass.size() != n
// or an index in `order` is not a valid spring index.
void gauss_seidel_sweep(Eigen::Matrix3Xd& x, const Eigen::VectorXd& inv_mass,
                        const std::vector<Spring>& springs, const std::vector<int>& order);

}  // namespace cl::lab02
