#pragma once
// A linear iteration with a known spectral radius, shared by the lab 11 tests:
// Jacobi on the n × n matrix tridiag(−1, 2, −1), three right-hand sides at
// once (the rows of a 3 × n array). Its iteration matrix B = I − D⁻¹A =
// tridiag(½, 0, ½) is symmetric with eigenvalues cos(jπ/(n+1)), j = 1 … n:
// spectral radius ρ = cos(π/(n+1)), reached at both ends of the spectrum.
#include <cmath>

#include <Eigen/Core>

namespace lab11_test {

constexpr double kPi = 3.14159265358979323846;

inline double splitting_rho(Eigen::Index n) { return std::cos(kPi / static_cast<double>(n + 1)); }

// x A for a 3 × n array x (A symmetric: each row of x times A).
inline Eigen::Matrix3Xd times_a(const Eigen::Matrix3Xd& x) {
  const Eigen::Index n = x.cols();
  Eigen::Matrix3Xd ax = 2.0 * x;
  for (Eigen::Index p = 0; p < n; ++p) {
    if (p > 0) ax.col(p) -= x.col(p - 1);
    if (p + 1 < n) ax.col(p) -= x.col(p + 1);
  }
  return ax;
}

// One Jacobi iteration for x A = b: x̂ = x + (b − x A) / 2.
inline Eigen::Matrix3Xd jacobi(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& b) {
  return x + 0.5 * (b - times_a(x));
}

// The eigenvector of B for cos(jπ/(n+1)): sin(j p π/(n+1)), p = 1 … n, in every row.
inline Eigen::Matrix3Xd mode(Eigen::Index n, int j) {
  Eigen::Matrix3Xd v(3, n);
  for (Eigen::Index p = 0; p < n; ++p) {
    v.col(p).setConstant(std::sin(j * static_cast<double>(p + 1) * kPi / static_cast<double>(n + 1)));
  }
  return v;
}

// T_k(z) for z >= 1: cosh(k arccosh z).
inline double chebyshev_t(int k, double z) { return std::cosh(k * std::acosh(z)); }

}  // namespace lab11_test
