// The fixed-pattern matrix of spring blocks (spring_blocks.h).
#include "common/spring_blocks.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace cl {

SpringBlockMatrix::SpringBlockMatrix(const MovableMap& map, const std::vector<Spring>& springs) {
  const auto particles = static_cast<int>(map.unknown_of.size());
  const Eigen::Index size = 3 * static_cast<Eigen::Index>(map.unknowns());
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const Spring& s = springs[e];
    if (s.i < 0 || s.j < 0 || s.i >= particles || s.j >= particles) {
      throw std::invalid_argument("SpringBlockMatrix: springs[" + std::to_string(e) + "] has an index out of range (" +
                                  std::to_string(s.i) + ", " + std::to_string(s.j) + ") for " +
                                  std::to_string(particles) + " particles");
    }
    if (s.i == s.j) {
      throw std::invalid_argument("SpringBlockMatrix: springs[" + std::to_string(e) + "] joins particle " +
                                  std::to_string(s.i) + " to itself");
    }
  }
  std::vector<Triplet> pattern;
  pattern.reserve(static_cast<std::size_t>(size) + kSlotsPerSpring * springs.size());
  for (Eigen::Index k = 0; k < size; ++k) pattern.emplace_back(k, k, 0.0);
  auto add_block = [&](int a, int b) {
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) pattern.emplace_back(3 * a + r, 3 * b + c, 0.0);
    }
  };
  for (const Spring& s : springs) {
    const int a = map.unknown_of[static_cast<std::size_t>(s.i)];
    const int b = map.unknown_of[static_cast<std::size_t>(s.j)];
    if (a >= 0) add_block(a, a);
    if (b >= 0) add_block(b, b);
    if (a >= 0 && b >= 0) {
      add_block(a, b);
      add_block(b, a);
    }
  }
  matrix_.resize(size, size);
  matrix_.setFromTriplets(pattern.begin(), pattern.end());  // explicit zeros are kept: the pattern
  matrix_.makeCompressed();
  const int* outer = matrix_.outerIndexPtr();
  const int* inner = matrix_.innerIndexPtr();
  auto index_of = [&](int row, int col) {
    return static_cast<int>(std::lower_bound(inner + outer[col], inner + outer[col + 1], row) - inner);
  };
  diagonal_.resize(static_cast<std::size_t>(size));
  for (int k = 0; k < static_cast<int>(size); ++k) diagonal_[static_cast<std::size_t>(k)] = index_of(k, k);
  slots_.assign(kSlotsPerSpring * springs.size(), -1);
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const int a = map.unknown_of[static_cast<std::size_t>(springs[e].i)];
    const int b = map.unknown_of[static_cast<std::size_t>(springs[e].j)];
    int* slot = slots_.data() + kSlotsPerSpring * e;
    const int rows[4] = {a, b, a, b};
    const int cols[4] = {a, b, b, a};
    for (int block = 0; block < 4; ++block) {
      if (rows[block] < 0 || cols[block] < 0) continue;
      for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r) slot[9 * block + 3 * c + r] = index_of(3 * rows[block] + r, 3 * cols[block] + c);
      }
    }
  }
}

void SpringBlockMatrix::set_zero() {
  double* value = matrix_.valuePtr();
  std::fill(value, value + matrix_.nonZeros(), 0.0);
}

void SpringBlockMatrix::add_diagonal(int unknown, double value) {
  double* values = matrix_.valuePtr();
  for (int r = 0; r < 3; ++r) values[diagonal_[static_cast<std::size_t>(3 * unknown + r)]] += value;
}

void SpringBlockMatrix::add_spring(std::size_t spring, const Eigen::Matrix3d& block) {
  const int* slot = slots_.data() + kSlotsPerSpring * spring;
  double* value = matrix_.valuePtr();
  const double sign[4] = {1.0, 1.0, -1.0, -1.0};
  for (int b = 0; b < 4; ++b) {
    if (slot[9 * b] < 0) continue;
    for (int k = 0; k < 9; ++k) value[slot[9 * b + k]] += sign[b] * block.data()[k];
  }
}

}  // namespace cl
