#pragma once
// Lab 10 — hierarchical position based dynamics. The contract for the student's
// code. Derivation: labs/lab10_hierarchical_pbd/README.md. Source: Müller,
// "Hierarchical Position Based Dynamics" (2008), §4 (the hierarchy, unilateral
// coarse constraints, the coarse-to-fine solve).
//
// Units: positions in m, inverse masses in 1/kg (0 = pinned), lengths in m.
// The hierarchy (levels, their constraints, masses, parents and weights) is
// built by common/hierarchy.h; this lab solves on it.
#include <vector>

#include <Eigen/Core>

#include "common/hierarchy.h"
#include "single_spring.h"

namespace cl::lab10 {

// TODO(lab10.1) — project one UNILATERAL distance constraint
//     C = max(0, ‖x_i − x_j‖ − L) = 0,
// which only resists stretch. With d = x_i − x_j:
//   - ‖d‖ <= L (compressed or exact): nothing to do, both corrections are zero;
//   - ‖d‖ >  L (stretched): lab01's projection, so that afterwards
//     ‖(x_i + Δx_i) − (x_j + Δx_j)‖ = L and the lighter end moves more:
//         Δx_i = −w_i/(w_i + w_j) · (‖d‖ − L) · d/‖d‖,   Δx_j = +w_j/(w_i + w_j) · (‖d‖ − L) · d/‖d‖.
// Degenerate input is a no-op as in lab 01 (both ends pinned; coincident
// particles are never stretched). Throws std::invalid_argument for a negative
// or non-finite inverse mass or rest length.
lab01::DistanceCorrection project_unilateral_distance(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j,
                                                      double inv_mass_i, double inv_mass_j, double rest_length);

// TODO(lab10.2) — prolong the corrections of a coarser level to a finer one.
//
// `start` holds the positions at the start of the coarse-to-fine solve, `x` the
// current ones; a coarse particle's correction is Δx_j = x_j − start_j (all it
// has moved so far, on its own level and the coarser ones). For every entry e
// of `prolongation` (HierarchyLevel::prolongation of the FINER level) whose
// particle is movable (inv_mass[e.particle] > 0):
//     x_e.particle += Σ_k e.weights[k] · (x_{e.parents[k]} − start_{e.parents[k]}).
// Nothing else changes: pinned particles and the coarse particles themselves stay put.
//
// Shapes: x and start are 3 × n, inv_mass has n entries (the finer level's).
// Throws std::invalid_argument when the shapes disagree, an index is not in
// [0, n), or an entry has different numbers of parents and weights.
void prolong_corrections(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& start,
                         const std::vector<Interpolation>& prolongation, const Eigen::VectorXd& inv_mass);

// TODO(lab10.3) — the coarse-to-fine solve, one pass.
//
// iterations[l] is the number of sweeps on level l (levels[0] the cloth,
// levels.back() the coarsest). Remember start = x, then for l from the
// coarsest level down to 0:
//   - l >= 1: iterations[l] sweeps over levels[l].springs in file order, each
//     spring projected with project_unilateral_distance and levels[l].inv_mass,
//     the corrections applied at once (Gauss-Seidel, as lab 02); then
//     prolong_corrections(x, start, levels[l − 1].prolongation, levels[l − 1].inv_mass);
//   - l = 0: iterations[0] sweeps of lab02::gauss_seidel_sweep over
//     levels[0].springs (bilateral: the cloth's own constraints) in file order
//     with levels[0].inv_mass.
// With one level this is exactly lab 04's Gauss-Seidel projection.
//
// Shapes: x is 3 × n, every level's inv_mass has n entries. Throws
// std::invalid_argument, before changing x, when iterations.size() differs
// from the number of levels, an entry is negative, or the inv_mass of any
// level, the coarse ones included, does not have x.cols() entries.
void solve_hierarchy(Eigen::Matrix3Xd& x, const ClothHierarchy& hierarchy, const std::vector<int>& iterations);

}  // namespace cl::lab10
