#pragma once
// The coarse-to-fine hierarchy of a cloth grid for hierarchical position based
// dynamics (Müller, "Hierarchical Position Based Dynamics", 2008, §4). Lab 10
// solves on it; the derivation is in labs/lab10_hierarchical_pbd/README.md.
//
// Every level is a sub-grid of the cloth: level l+1 keeps every other grid line
// of level l in each direction, plus the last one, so the borders (and the
// corners, where the curtains are pinned) are on every level. A coarse particle
// is the same particle as the fine one it was kept from, so all levels index
// the one particle array, in scene order.
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"

namespace cl {

// How one particle of a finer level follows the next coarser level:
//     Δx_particle = Σ_k weights[k] · Δx_parents[k].
// The parents are the 1, 2 or 4 coarse particles at the corners of the coarse
// grid cell (or edge) the particle lies in; the weights are bilinear in the
// grid indices (the cloth grid is uniform, so bilinear in the rest shape),
// positive, and sum to 1.
struct Interpolation {
  int particle = 0;             // scene index
  std::vector<int> parents;     // scene indices, 1, 2 or 4 of them
  std::vector<double> weights;  // one per parent, > 0, sum 1
};

struct HierarchyLevel {
  int nx = 0;                // grid lines of this level across (columns) …
  int ny = 0;                // … and down (rows)
  std::vector<int> columns;  // the cloth column of each of this level's columns, ascending
  std::vector<int> rows;     // the cloth row of each of this level's rows, ascending
  std::vector<int> particles;  // this level's particles (scene indices), row-major over (rows, columns)
  // Inverse masses for the whole particle array (1/kg): this level's values at
  // its particles, 0 at particles that are not on this level. 0 also means pinned.
  Eigen::VectorXd inv_mass;
  // Level 0: the scene's springs, as given. Coarser levels: structural and
  // shear constraints of the level's grid (right and down neighbours, both
  // diagonals of every cell), rest length = distance in the rest shape,
  // stiffness infinite; lab 10 makes them unilateral (they resist stretch only).
  std::vector<Spring> springs;
  // The particles of this level that are NOT on the next coarser one, each with
  // its parents there. Empty on the coarsest level.
  std::vector<Interpolation> prolongation;
};

struct ClothHierarchy {
  std::vector<HierarchyLevel> levels;  // levels[0] is the cloth itself, levels.back() the coarsest
  int level_count() const { return static_cast<int>(levels.size()); }
};

// The grid lines a coarser level keeps of `count` lines: 0, 2, 4, … and the
// last one (count − 1) when it is not already among them. Needs count >= 3
// (2 lines cannot get any coarser).
std::vector<int> coarser_lines(int count);

// The most levels an nx × ny grid supports (1 for the grid itself, one more for
// every coarsening while both directions still have at least 3 lines).
int max_levels(int nx, int ny);

// Builds `levels` levels of the cloth grid nx × ny (particle index row·nx + col,
// as the scene's cloth generator lays them out).
//
//   rest_positions  3 × n, n = nx·ny: the rest shape; the coarse constraints'
//                   rest lengths are distances in it. (Pass the initial
//                   positions of an unperturbed cloth; a jitter would enter them.)
//   inv_mass        n entries, 1/kg, 0 = pinned.
//   springs         the cloth's own constraints, copied to level 0.
//
// Masses: a coarse particle starts with its own (finer-level) mass and gets
// weight · m of every movable finer particle it parents (the weights of a
// finer particle sum to 1). The share that lands on a pinned coarse particle
// no longer moves, so next to pins a level's movable mass is a little below
// the finer one's (lab 10's run prints each level's). A particle pinned on the finer level is
// pinned on every level it is on (inverse mass 0 stays 0); a pinned particle
// that is not on the coarser level passes no mass up (it never moves).
//
// Throws std::invalid_argument for nx or ny < 2, n != nx·ny, inv_mass of the
// wrong size or with an entry that is negative or not finite, levels < 1 or
// levels > max_levels(nx, ny).
ClothHierarchy build_cloth_hierarchy(int nx, int ny, const Eigen::Matrix3Xd& rest_positions,
                                     const Eigen::VectorXd& inv_mass, const std::vector<Spring>& springs,
                                     int levels);

}  // namespace cl
