// Lab 11 — reference solution.
#include "acceleration.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace cl::lab11 {

namespace {

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

}  // namespace

double chebyshev_weight(int j, double rho, double previous_omega) {
  if (j < 1) throw std::invalid_argument("chebyshev_weight: j must be >= 1 (got " + std::to_string(j) + ")");
  if (!std::isfinite(rho) || rho < 0.0 || rho >= 1.0) {
    throw std::invalid_argument("chebyshev_weight: rho must be finite and in [0, 1) (got " + number(rho) + ")");
  }
  if (j == 1) return 1.0;
  if (j == 2) return 2.0 / (2.0 - rho * rho);
  if (!std::isfinite(previous_omega) || previous_omega < 1.0 || previous_omega >= 2.0) {
    throw std::invalid_argument("chebyshev_weight: previous_omega must be finite and in [1, 2) (got " +
                                number(previous_omega) + ")");
  }
  return 4.0 / (4.0 - rho * rho * previous_omega);
}

Eigen::Matrix3Xd chebyshev_update(const Eigen::Matrix3Xd& q_hat, const Eigen::Matrix3Xd& q,
                                  const Eigen::Matrix3Xd& q_previous, double omega, double gamma) {
  if (q.cols() != q_hat.cols() || q_previous.cols() != q_hat.cols()) {
    throw std::invalid_argument("chebyshev_update: q_hat, q and q_previous have " + std::to_string(q_hat.cols()) +
                                ", " + std::to_string(q.cols()) + " and " + std::to_string(q_previous.cols()) +
                                " columns");
  }
  if (!std::isfinite(omega) || omega < 1.0 || omega >= 2.0) {
    throw std::invalid_argument("chebyshev_update: omega must be finite and in [1, 2) (got " + number(omega) + ")");
  }
  if (!std::isfinite(gamma) || !(gamma > 0.0) || !(gamma < 2.0)) {
    throw std::invalid_argument("chebyshev_update: gamma must be finite and in (0, 2) (got " + number(gamma) + ")");
  }
  Eigen::Matrix3Xd next = (omega * gamma) * q_hat;
  next += (omega * (1.0 - gamma)) * q;
  next += (1.0 - omega) * q_previous;
  return next;
}

double estimate_spectral_radius(const std::vector<double>& update_norms) {
  const std::size_t n = update_norms.size();
  if (n < 2) {
    throw std::invalid_argument("estimate_spectral_radius: needs at least 2 update lengths (got " +
                                std::to_string(n) + ")");
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(update_norms[k]) || update_norms[k] < 0.0) {
      throw std::invalid_argument("estimate_spectral_radius: update_norms[" + std::to_string(k) +
                                  "] must be finite and >= 0 (got " + number(update_norms[k]) + ")");
    }
  }
  const std::size_t window = n / 2;
  const double last = update_norms[n - 1];
  const double first = update_norms[n - 1 - window];
  if (last == 0.0 || first == 0.0) return 0.0;
  return std::pow(last / first, 1.0 / static_cast<double>(window));
}

bool restart_needed(double objective_before, double objective_after, double slack) {
  if (!std::isfinite(objective_before)) {
    throw std::invalid_argument("restart_needed: objective_before must be finite (got " + number(objective_before) +
                                ")");
  }
  if (!std::isfinite(slack) || slack < 0.0) {
    throw std::invalid_argument("restart_needed: slack must be finite and >= 0 (got " + number(slack) + ")");
  }
  if (!std::isfinite(objective_after)) return true;
  return objective_after > objective_before + slack * std::abs(objective_before);
}

Eigen::VectorXd lbfgs_direction(const Eigen::VectorXd& gradient, const std::vector<CurvaturePair>& pairs,
                                const InverseApply& initial_inverse) {
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (pairs[i].s.size() != gradient.size() || pairs[i].y.size() != gradient.size()) {
      throw std::invalid_argument("lbfgs_direction: pairs[" + std::to_string(i) + "] has sizes " +
                                  std::to_string(pairs[i].s.size()) + " and " + std::to_string(pairs[i].y.size()) +
                                  ", the gradient " + std::to_string(gradient.size()));
    }
  }
  std::vector<double> curvature(pairs.size()), alpha(pairs.size(), 0.0);
  for (std::size_t i = 0; i < pairs.size(); ++i) curvature[i] = pairs[i].s.dot(pairs[i].y);
  const auto used = [&](std::size_t i) { return std::isfinite(curvature[i]) && curvature[i] > 0.0; };
  Eigen::VectorXd q = gradient;
  for (std::size_t i = pairs.size(); i-- > 0;) {
    if (!used(i)) continue;
    alpha[i] = pairs[i].s.dot(q) / curvature[i];
    q -= alpha[i] * pairs[i].y;
  }
  Eigen::VectorXd r = initial_inverse(q);
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (!used(i)) continue;
    const double beta = pairs[i].y.dot(r) / curvature[i];
    r += (alpha[i] - beta) * pairs[i].s;
  }
  return -r;
}

}  // namespace cl::lab11
