#pragma once
// Sparse tools shared by the implicit labs (06 projective dynamics, 07 KKT and
// Schur, 09 geometric stiffness): which particles are unknowns, assembly from
// triplets, and one symmetric positive definite factorization reused for many
// solves. Derivations: labs/lab06_projective_dynamics/README.md.
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace cl {

using SparseMatrix = Eigen::SparseMatrix<double>;  // column-major
using Triplet = Eigen::Triplet<double>;
// One row per unknown, one column per coordinate (x, y, z); row-major so that
// an unknown's three values sit together in memory.
using RowsX3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

// Pinned particles (inverse mass 0) are not unknowns: their positions are data.
// Unknowns are the movable particles in scene order.
struct MovableMap {
  std::vector<int> unknown_of;   // per particle: its unknown index, or -1 when pinned
  std::vector<int> particle_of;  // per unknown: its particle index
  int unknowns() const { return static_cast<int>(particle_of.size()); }
};

// Builds the map from inverse masses (> 0: movable). Throws std::invalid_argument
// for a negative or non-finite inverse mass.
MovableMap make_movable_map(const Eigen::VectorXd& inv_mass);

// A rows × cols sparse matrix from triplets; duplicates are summed (that is how
// per-element contributions add up). Throws std::invalid_argument, naming the
// triplet, for an index out of range or a non-finite value.
SparseMatrix assemble(Eigen::Index rows, Eigen::Index cols, const std::vector<Triplet>& triplets);

// Unknown rows of a 3 × n per-particle array (positions, velocities, forces).
RowsX3 gather_rows(const Eigen::Matrix3Xd& values, const MovableMap& map);
// Writes unknown rows back into the movable columns; pinned columns are untouched.
void scatter_rows(const RowsX3& rows, const MovableMap& map, Eigen::Matrix3Xd& values);

// The same, stacked as one vector of 3 entries per unknown (x, y, z), for
// systems that couple the coordinates (a Jacobian's columns 3u, 3u+1, 3u+2).
Eigen::VectorXd gather_stacked(const Eigen::Matrix3Xd& values, const MovableMap& map);
void scatter_stacked(const Eigen::VectorXd& stacked, const MovableMap& map, Eigen::Matrix3Xd& values);

// A sparse LDLᵀ factorization (Eigen's SimplicialLDLT, AMD ordering) of a
// symmetric positive definite matrix, kept for many solves.
class SpdFactorization {
 public:
  // Factors `a` (square, symmetric; the lower triangle is read). Returns false,
  // and keeps no factor, when `a` is not positive definite to working
  // precision (a pivot of D that is not finite and > 0), e.g. a singular Schur
  // complement. Counts every call in factorizations().
  bool factor(const SparseMatrix& a);
  // The same for a matrix whose values changed but whose sparsity pattern did
  // not (Newton's Hessian, a KKT matrix): the ordering and symbolic analysis
  // of the last factor() are reused and only the numeric factorization is
  // redone. When the pattern differs (or nothing was factored yet) it is
  // factor(a). Counts in factorizations() like factor().
  bool refactor(const SparseMatrix& a);
  bool ok() const { return ok_; }
  int factorizations() const { return factorizations_; }
  Eigen::Index size() const { return size_; }

  // Solves A X = B for three right-hand sides at once in ONE pass over the
  // factor: each entry of L is loaded once and applied to all three columns.
  // Throws std::logic_error without a factor and std::invalid_argument when B
  // has the wrong number of rows.
  RowsX3 solve3(const RowsX3& b) const;
  // One right-hand side. Same errors.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;

  // Eigen's own object, e.g. to compare with Eigen's column-by-column solve.
  const Eigen::SimplicialLDLT<SparseMatrix>& eigen() const { return ldlt_; }

 private:
  void require_factor(Eigen::Index rows) const;
  bool same_pattern(const SparseMatrix& a) const;
  bool accept_pivots(Eigen::Index rows);

  Eigen::SimplicialLDLT<SparseMatrix> ldlt_;
  bool ok_ = false;
  int factorizations_ = 0;
  Eigen::Index size_ = 0;
  // The pattern the symbolic analysis was made for (compressed column arrays).
  std::vector<int> analyzed_outer_, analyzed_inner_;
};

}  // namespace cl
