// Lab 13 — reference solution.
#include "constrained_newton.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "constrained.h"

namespace cl::lab13 {

namespace {

void require_dt(const char* function, double dt) {
  if (!std::isfinite(dt) || !(dt > 0.0)) {
    throw std::invalid_argument(std::string(function) + ": dt must be finite and > 0 (got " + std::to_string(dt) +
                                ")");
  }
}

void require_columns(const char* function, const char* what, Eigen::Index got, Eigen::Index want) {
  if (got != want) {
    throw std::invalid_argument(std::string(function) + ": " + what + " has " + std::to_string(got) +
                                " entries, expected " + std::to_string(want));
  }
}

// NaN when any entry is NaN (Eigen's default maxCoeff may skip one).
double max_abs(const Eigen::VectorXd& v) {
  return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff<Eigen::PropagateNaN>();
}

}  // namespace

Residuals residuals(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const Eigen::VectorXd& lambda,
                    const std::vector<Spring>& springs, const Eigen::VectorXd& inv_mass, const MovableMap& map,
                    const Eigen::VectorXd& compliance, double dt) {
  const Eigen::Index n = x.cols();
  const auto m = static_cast<Eigen::Index>(springs.size());
  require_columns("residuals", "y", y.cols(), n);
  require_columns("residuals", "inv_mass", inv_mass.size(), n);
  require_columns("residuals", "map", static_cast<Eigen::Index>(map.unknown_of.size()), n);
  require_columns("residuals", "lambda", lambda.size(), m);
  if (compliance.size() != 0) require_columns("residuals", "compliance", compliance.size(), m);
  require_dt("residuals", dt);

  Residuals r;
  const Eigen::Index u = map.unknowns();
  r.inertia.resize(3 * u);
  for (Eigen::Index k = 0; k < u; ++k) {
    const int p = map.particle_of[static_cast<std::size_t>(k)];
    r.inertia.segment<3>(3 * k) = (x.col(p) - y.col(p)) / (inv_mass[p] * dt * dt);
  }
  // φ (lab07::constraint_values checks the springs), then Jᵀλ spring by
  // spring: row e of lab07::constraint_jacobian is +n_e on i's unknown and
  // −n_e on j's (none for coincident ends), so λ_e n_e adds to i and
  // subtracts from j. No J is assembled: the line search calls this once per
  // trial step.
  r.constraint = lab07::constraint_values(x, springs);
  r.constraint_force = Eigen::VectorXd::Zero(3 * u);
  for (std::size_t e = 0; e < springs.size(); ++e) {
    const Spring& s = springs[e];
    const Eigen::Vector3d d = x.col(s.i) - x.col(s.j);
    const double length = d.norm();
    if (!(length > 0.0)) continue;
    const Eigen::Vector3d pull = lambda[static_cast<Eigen::Index>(e)] * (d / length);
    const int ui = map.unknown_of[static_cast<std::size_t>(s.i)];
    const int uj = map.unknown_of[static_cast<std::size_t>(s.j)];
    if (ui >= 0) r.constraint_force.segment<3>(3 * ui) += pull;
    if (uj >= 0) r.constraint_force.segment<3>(3 * uj) -= pull;
  }
  r.force = r.inertia - r.constraint_force;
  if (compliance.size() != 0) r.constraint += compliance.cwiseProduct(lambda);
  return r;
}

Eigen::VectorXd rebased_velocity(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, const MovableMap& map,
                                 const Eigen::Vector3d& gravity, double dt) {
  require_columns("rebased_velocity", "y", y.cols(), x.cols());
  require_columns("rebased_velocity", "map", static_cast<Eigen::Index>(map.unknown_of.size()), x.cols());
  require_dt("rebased_velocity", dt);
  Eigen::VectorXd velocity(3 * map.unknowns());
  for (int k = 0; k < map.unknowns(); ++k) {
    const int p = map.particle_of[static_cast<std::size_t>(k)];
    velocity.segment<3>(3 * k) = (y.col(p) - x.col(p)) / dt - dt * gravity;
  }
  return velocity;
}

Eigen::VectorXd warm_start(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs,
                           const Eigen::VectorXd& previous_lambda, Warm warm) {
  const auto m = static_cast<Eigen::Index>(springs.size());
  if (previous_lambda.size() != 0) require_columns("warm_start", "previous_lambda", previous_lambda.size(), m);
  if (!previous_lambda.allFinite()) throw std::invalid_argument("warm_start: previous_lambda is not finite");
  const Eigen::VectorXd phi = lab07::constraint_values(x, springs);  // validates the springs
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m);
  if (warm == Warm::kZero) return lambda;
  for (Eigen::Index e = 0; e < m; ++e) {
    const double k = springs[static_cast<std::size_t>(e)].stiffness;
    if (std::isfinite(k)) {
      lambda[e] = -k * phi[e];
    } else if (previous_lambda.size() == m) {
      lambda[e] = previous_lambda[e];
    }
  }
  return lambda;
}

Convergence convergence(const Residuals& residuals, double length_scale, double tolerance) {
  if (!std::isfinite(length_scale) || !(length_scale > 0.0)) {
    throw std::invalid_argument("convergence: length_scale must be finite and > 0 (got " +
                                std::to_string(length_scale) + ")");
  }
  if (!std::isfinite(tolerance) || tolerance < 0.0) {
    throw std::invalid_argument("convergence: tolerance must be finite and >= 0 (got " + std::to_string(tolerance) +
                                ")");
  }
  if (residuals.inertia.size() != residuals.force.size() ||
      residuals.constraint_force.size() != residuals.force.size()) {
    throw std::invalid_argument("convergence: force, inertia and constraint_force differ in size");
  }
  Convergence c;
  const double imbalance = max_abs(residuals.force);
  const double scale = std::max(max_abs(residuals.inertia), max_abs(residuals.constraint_force));
  c.force_error = imbalance == 0.0 ? 0.0 : imbalance / scale;
  c.constraint_error = max_abs(residuals.constraint) / length_scale;
  c.converged = c.force_error <= tolerance && c.constraint_error <= tolerance;
  return c;
}

Eigen::VectorXd merit_weights(const std::vector<Spring>& springs, const Eigen::VectorXd& inv_mass,
                              const Eigen::VectorXd& compliance, double dt) {
  const auto m = static_cast<Eigen::Index>(springs.size());
  if (compliance.size() != 0) require_columns("merit_weights", "compliance", compliance.size(), m);
  require_dt("merit_weights", dt);
  Eigen::VectorXd weights(m);
  for (Eigen::Index e = 0; e < m; ++e) {
    const Spring& s = springs[static_cast<std::size_t>(e)];
    if (s.i < 0 || s.j < 0 || s.i >= inv_mass.size() || s.j >= inv_mass.size()) {
      throw std::invalid_argument("merit_weights: springs[" + std::to_string(e) + "] has an index out of range");
    }
    const double c = compliance.size() == 0 ? 0.0 : compliance[e];
    const double denominator = c + dt * dt * (inv_mass[s.i] + inv_mass[s.j]);
    weights[e] = denominator > 0.0 ? 1.0 / denominator : 0.0;
  }
  return weights;
}

double merit(const Residuals& residuals, const Eigen::VectorXd& inv_mass, const MovableMap& map,
             const Eigen::VectorXd& weights, double dt) {
  require_dt("merit", dt);
  require_columns("merit", "force", residuals.force.size(), 3 * static_cast<Eigen::Index>(map.unknowns()));
  require_columns("merit", "weights", weights.size(), residuals.constraint.size());
  double inertial = 0.0;
  for (Eigen::Index k = 0; k < residuals.force.size(); ++k) {
    const int p = map.particle_of[static_cast<std::size_t>(k / 3)];
    inertial += inv_mass[p] * residuals.force[k] * residuals.force[k];
  }
  const double constraint = weights.dot(residuals.constraint.cwiseAbs2());
  return 0.5 * dt * dt * inertial + 0.5 * constraint;
}

bool sufficient_decrease(double merit_before, double merit_after, double alpha) {
  if (!(alpha > 0.0) || alpha > 1.0) {
    throw std::invalid_argument("sufficient_decrease: alpha must be in (0, 1] (got " + std::to_string(alpha) + ")");
  }
  if (!std::isfinite(merit_before) || merit_before < 0.0) {
    throw std::invalid_argument("sufficient_decrease: merit_before must be finite and >= 0 (got " +
                                std::to_string(merit_before) + ")");
  }
  if (!std::isfinite(merit_after)) return false;
  return merit_after <= (1.0 - 2.0 * kArmijo * alpha) * merit_before;
}

}  // namespace cl::lab13
