#include "common/sparse.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace cl {

MovableMap make_movable_map(const Eigen::VectorXd& inv_mass) {
  MovableMap map;
  map.unknown_of.assign(static_cast<std::size_t>(inv_mass.size()), -1);
  for (Eigen::Index p = 0; p < inv_mass.size(); ++p) {
    const double w = inv_mass[p];
    if (!std::isfinite(w) || w < 0.0) {
      throw std::invalid_argument("make_movable_map: inv_mass[" + std::to_string(p) +
                                  "] must be finite and >= 0 (got " + std::to_string(w) + ")");
    }
    if (w > 0.0) {
      map.unknown_of[static_cast<std::size_t>(p)] = map.unknowns();
      map.particle_of.push_back(static_cast<int>(p));
    }
  }
  return map;
}

SparseMatrix assemble(Eigen::Index rows, Eigen::Index cols, const std::vector<Triplet>& triplets) {
  for (std::size_t t = 0; t < triplets.size(); ++t) {
    const Triplet& entry = triplets[t];
    if (entry.row() < 0 || entry.row() >= rows || entry.col() < 0 || entry.col() >= cols) {
      throw std::invalid_argument("assemble: triplet " + std::to_string(t) + " at (" +
                                  std::to_string(entry.row()) + ", " + std::to_string(entry.col()) +
                                  ") is outside " + std::to_string(rows) + " x " + std::to_string(cols));
    }
    if (!std::isfinite(entry.value())) {
      throw std::invalid_argument("assemble: triplet " + std::to_string(t) + " is not finite");
    }
  }
  SparseMatrix matrix(rows, cols);
  matrix.setFromTriplets(triplets.begin(), triplets.end());  // sums duplicates
  return matrix;
}

RowsX3 gather_rows(const Eigen::Matrix3Xd& values, const MovableMap& map) {
  RowsX3 rows(map.unknowns(), 3);
  for (int u = 0; u < map.unknowns(); ++u) rows.row(u) = values.col(map.particle_of[static_cast<std::size_t>(u)]).transpose();
  return rows;
}

void scatter_rows(const RowsX3& rows, const MovableMap& map, Eigen::Matrix3Xd& values) {
  for (int u = 0; u < map.unknowns(); ++u) values.col(map.particle_of[static_cast<std::size_t>(u)]) = rows.row(u).transpose();
}

Eigen::VectorXd gather_stacked(const Eigen::Matrix3Xd& values, const MovableMap& map) {
  Eigen::VectorXd stacked(3 * map.unknowns());
  for (int u = 0; u < map.unknowns(); ++u) {
    stacked.segment<3>(3 * u) = values.col(map.particle_of[static_cast<std::size_t>(u)]);
  }
  return stacked;
}

void scatter_stacked(const Eigen::VectorXd& stacked, const MovableMap& map, Eigen::Matrix3Xd& values) {
  for (int u = 0; u < map.unknowns(); ++u) {
    values.col(map.particle_of[static_cast<std::size_t>(u)]) = stacked.segment<3>(3 * u);
  }
}

bool SpdFactorization::factor(const SparseMatrix& a) {
  ++factorizations_;
  ok_ = false;
  size_ = 0;
  if (a.rows() != a.cols()) {
    throw std::invalid_argument("SpdFactorization::factor: the matrix is " + std::to_string(a.rows()) + " x " +
                                std::to_string(a.cols()) + ", not square");
  }
  SparseMatrix copy;
  const SparseMatrix* matrix = &a;
  if (!a.isCompressed()) {
    copy = a;
    copy.makeCompressed();
    matrix = &copy;
  }
  ldlt_.analyzePattern(*matrix);
  analyzed_outer_.assign(matrix->outerIndexPtr(), matrix->outerIndexPtr() + matrix->outerSize() + 1);
  analyzed_inner_.assign(matrix->innerIndexPtr(), matrix->innerIndexPtr() + matrix->nonZeros());
  ldlt_.factorize(*matrix);
  return accept_pivots(a.rows());
}

bool SpdFactorization::same_pattern(const SparseMatrix& a) const {
  if (a.rows() != a.cols() || a.outerSize() + 1 != static_cast<Eigen::Index>(analyzed_outer_.size())) return false;
  if (!a.isCompressed()) return false;
  return std::equal(analyzed_outer_.begin(), analyzed_outer_.end(), a.outerIndexPtr()) &&
         a.nonZeros() == static_cast<Eigen::Index>(analyzed_inner_.size()) &&
         std::equal(analyzed_inner_.begin(), analyzed_inner_.end(), a.innerIndexPtr());
}

bool SpdFactorization::refactor(const SparseMatrix& a) {
  if (analyzed_outer_.empty() || !same_pattern(a)) return factor(a);
  ++factorizations_;
  ok_ = false;
  size_ = 0;
  ldlt_.factorize(a);
  return accept_pivots(a.rows());
}

bool SpdFactorization::accept_pivots(Eigen::Index rows) {
  if (ldlt_.info() != Eigen::Success) return false;
  const Eigen::VectorXd& d = ldlt_.vectorD();
  // A pivot that is not clearly positive means A is singular or indefinite to
  // working precision; solving with it would amplify round-off without bound.
  const double largest = d.size() > 0 ? d.cwiseAbs().maxCoeff() : 0.0;
  const double floor = largest * static_cast<double>(d.size()) * 1e-15;
  for (Eigen::Index k = 0; k < d.size(); ++k) {
    if (!std::isfinite(d[k]) || !(d[k] > floor)) return false;
  }
  ok_ = true;
  size_ = rows;
  return true;
}

void SpdFactorization::require_factor(Eigen::Index rows) const {
  if (!ok_) throw std::logic_error("SpdFactorization: no factor (factor() failed or was not called)");
  if (rows != size_) {
    throw std::invalid_argument("SpdFactorization: right-hand side has " + std::to_string(rows) +
                                " rows, the factor " + std::to_string(size_));
  }
}

RowsX3 SpdFactorization::solve3(const RowsX3& b) const {
  require_factor(b.rows());
  // A = Pᵀ L D Lᵀ P with L unit lower triangular, stored without its diagonal.
  // y = P b; L z = y; w = D⁻¹ z; Lᵀ u = w; x = Pᵀ u — each loop over L's
  // columns moves all three coordinates together.
  RowsX3 y = ldlt_.permutationP() * b;
  const SparseMatrix& lower = ldlt_.matrixL().nestedExpression();
  const int* outer = lower.outerIndexPtr();
  const int* inner = lower.innerIndexPtr();
  const double* value = lower.valuePtr();
  double* data = y.data();
  const Eigen::Index n = size_;
  for (Eigen::Index j = 0; j < n; ++j) {
    const double y0 = data[3 * j], y1 = data[3 * j + 1], y2 = data[3 * j + 2];
    for (int p = outer[j]; p < outer[j + 1]; ++p) {
      double* row = data + 3 * inner[p];
      row[0] -= value[p] * y0;
      row[1] -= value[p] * y1;
      row[2] -= value[p] * y2;
    }
  }
  const Eigen::VectorXd& d = ldlt_.vectorD();
  for (Eigen::Index j = 0; j < n; ++j) {
    const double inverse = 1.0 / d[j];
    data[3 * j] *= inverse;
    data[3 * j + 1] *= inverse;
    data[3 * j + 2] *= inverse;
  }
  for (Eigen::Index j = n - 1; j >= 0; --j) {
    double s0 = data[3 * j], s1 = data[3 * j + 1], s2 = data[3 * j + 2];
    for (int p = outer[j]; p < outer[j + 1]; ++p) {
      const double* row = data + 3 * inner[p];
      s0 -= value[p] * row[0];
      s1 -= value[p] * row[1];
      s2 -= value[p] * row[2];
    }
    data[3 * j] = s0;
    data[3 * j + 1] = s1;
    data[3 * j + 2] = s2;
  }
  return ldlt_.permutationPinv() * y;
}

Eigen::VectorXd SpdFactorization::solve(const Eigen::VectorXd& b) const {
  require_factor(b.rows());
  return ldlt_.solve(b);
}

}  // namespace cl
