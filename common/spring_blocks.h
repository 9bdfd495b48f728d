#pragma once
// A sparse matrix over the movable unknowns whose sparsity pattern is fixed
// by the springs: the diagonal, and for every spring the four 3 × 3 blocks
// (i,i), (j,j), (i,j), (j,i) among its movable ends. Lab 06's Newton Hessian
// (M/Δt² plus each spring's block) and lab 13's eliminated matrix
// (M − Δt² K_g + Δt² Jᵀ C⁻¹ J: the mass plus, per spring, one symmetric
// block) are both of this form. The pattern, and where each spring's blocks
// sit in it, are found once (the constructor); a refill writes the values in
// place, with no triplets and no sort. A spring's blocks are stored even when
// their values are 0, so the pattern never changes and a factorization's
// ordering and symbolic analysis hold for every refill
// (SpdFactorization::refactor, common/sparse.h).
#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/sparse.h"

namespace cl {

class SpringBlockMatrix {
 public:
  SpringBlockMatrix() = default;  // empty(): no pattern
  // The pattern for `springs` over map's unknowns (3 per unknown). Throws
  // std::invalid_argument, naming the spring, for an index out of range of
  // the map or a spring that joins a particle to itself.
  SpringBlockMatrix(const MovableMap& map, const std::vector<Spring>& springs);

  bool empty() const { return matrix_.rows() == 0 && slots_.empty(); }
  Eigen::Index rows() const { return matrix_.rows(); }
  std::size_t springs() const { return slots_.size() / kSlotsPerSpring; }

  // False when both ends of spring e are pinned (it has no block).
  bool has_block(std::size_t spring) const {
    return slots_[kSlotsPerSpring * spring] >= 0 || slots_[kSlotsPerSpring * spring + 9] >= 0;
  }
  // Every stored value to 0 (the pattern stays).
  void set_zero();
  // Adds `value` to the three diagonal entries of unknown u (0 ≤ u < unknowns).
  void add_diagonal(int unknown, double value);
  // Adds spring e's block S (3 × 3): +S at (i,i) and (j,j), −S at (i,j) and
  // (j,i), leaving out the rows and columns of a pinned end. S is read as it
  // is (column-major); the matrix stays symmetric when S is.
  void add_spring(std::size_t spring, const Eigen::Matrix3d& block);

  // Full (both triangles), compressed; the reference stays valid while this
  // object lives, its values change with every refill.
  const SparseMatrix& matrix() const { return matrix_; }

 private:
  static constexpr std::size_t kSlotsPerSpring = 36;  // blocks ii, jj, ij, ji, each 3 × 3 column-major
  SparseMatrix matrix_;
  std::vector<int> diagonal_;  // per stacked row: the value index of its diagonal entry
  std::vector<int> slots_;     // per spring: 36 value indices (−1: a pinned end's block)
};

}  // namespace cl
