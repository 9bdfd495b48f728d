// Lab 08 — reference solution.
#include "xpbd.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cl::lab08 {

namespace {
void require_finite_non_negative(double value, const char* name) {
  if (!(value >= 0.0) || !std::isfinite(value)) {
    throw std::invalid_argument(std::string("project_distance_xpbd: ") + name + " must be finite and >= 0 (got " +
                                std::to_string(value) + ")");
  }
}

// The formula alone, without the argument checks: project_distance_xpbd is
// its checks and this; xpbd_step checks every argument once per step, before
// its sweeps, and calls this inline, so that no projection pays for them.
inline XpbdCorrection xpbd_correction(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j, double inv_mass_i,
                                      double inv_mass_j, double rest_length, double alpha_tilde, double lambda) {
  XpbdCorrection correction;
  const Eigen::Vector3d d = x_i - x_j;
  const double length = d.norm();
  const double denominator = inv_mass_i + inv_mass_j + alpha_tilde;
  if (length == 0.0 || denominator == 0.0) return correction;
  const Eigen::Vector3d n = d / length;
  correction.dlambda = (-(length - rest_length) - alpha_tilde * lambda) / denominator;
  correction.dx_i = (inv_mass_i * correction.dlambda) * n;
  correction.dx_j = (-inv_mass_j * correction.dlambda) * n;
  return correction;
}

}  // namespace

XpbdCorrection project_distance_xpbd(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j, double inv_mass_i,
                                     double inv_mass_j, double rest_length, double alpha_tilde, double lambda) {
  require_finite_non_negative(inv_mass_i, "inv_mass_i");
  require_finite_non_negative(inv_mass_j, "inv_mass_j");
  require_finite_non_negative(rest_length, "rest_length");
  require_finite_non_negative(alpha_tilde, "alpha_tilde");
  if (!std::isfinite(lambda)) {
    throw std::invalid_argument("project_distance_xpbd: lambda must be finite (got " + std::to_string(lambda) + ")");
  }
  return xpbd_correction(x_i, x_j, inv_mass_i, inv_mass_j, rest_length, alpha_tilde, lambda);
}

void xpbd_step(Particles& particles, const lab04::ConstraintSet& constraints, const XpbdSettings& settings,
               Eigen::VectorXd& lambda) {
  const double dt = settings.dt;
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    throw std::invalid_argument("xpbd_step: dt must be finite and > 0 (got " + std::to_string(dt) + ")");
  }
  if (settings.iterations < 0) {
    throw std::invalid_argument("xpbd_step: iterations must be >= 0 (got " + std::to_string(settings.iterations) +
                                ")");
  }
  const Eigen::Index n = particles.size();
  if (particles.v.cols() != n || particles.inv_mass.size() != n) {
    throw std::invalid_argument("xpbd_step: x, v and inv_mass disagree in size");
  }
  for (Eigen::Index p = 0; p < n; ++p) {
    const double w = particles.inv_mass[p];
    if (!std::isfinite(w) || w < 0.0) {
      throw std::invalid_argument("xpbd_step: inv_mass[" + std::to_string(p) + "] must be finite and >= 0 (got " +
                                  std::to_string(w) + ")");
    }
  }
  const std::vector<Spring>& springs = constraints.springs;
  const auto spring_count = static_cast<int>(springs.size());
  std::vector<double> alpha_tilde(springs.size());
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const Spring& spring = springs[s];
    if (spring.i < 0 || spring.i >= n || spring.j < 0 || spring.j >= n) {
      throw std::invalid_argument("xpbd_step: spring " + std::to_string(s) + " has a particle index out of range");
    }
    if (!std::isfinite(spring.rest_length) || spring.rest_length < 0.0) {
      throw std::invalid_argument("xpbd_step: spring " + std::to_string(s) + " has rest length " +
                                  std::to_string(spring.rest_length) + ", not finite and >= 0");
    }
    alpha_tilde[s] = compliance(spring) / (dt * dt);
    if (!std::isfinite(alpha_tilde[s])) {
      throw std::invalid_argument("xpbd_step: spring " + std::to_string(s) + ": alpha_tilde = compliance / dt^2 "
                                  "overflows at dt = " + std::to_string(dt));
    }
  }
  for (const int s : constraints.order) {
    if (s < 0 || s >= spring_count) {
      throw std::invalid_argument("xpbd_step: order holds " + std::to_string(s) + ", not a spring index");
    }
  }

  // Symplectic Euler for the unconstrained system, as lab 04; the particles
  // are written only at the end.
  Eigen::Matrix3Xd predicted = particles.x;
  for (Eigen::Index p = 0; p < n; ++p) {
    if (particles.inv_mass[p] > 0.0) {
      const Eigen::Vector3d velocity = particles.v.col(p) + dt * settings.gravity;
      predicted.col(p) += dt * velocity;
    }
  }

  // λ belongs to the step: it starts from 0 here and accumulates over all K sweeps.
  // Everything project_distance_xpbd checks was checked above, once: the
  // sweeps call its formula directly.
  lambda.setZero(spring_count);
  for (int k = 0; k < settings.iterations; ++k) {
    for (const int s : constraints.order) {
      const Spring& spring = springs[static_cast<std::size_t>(s)];
      const XpbdCorrection correction = xpbd_correction(
          predicted.col(spring.i), predicted.col(spring.j), particles.inv_mass[spring.i],
          particles.inv_mass[spring.j], spring.rest_length, alpha_tilde[static_cast<std::size_t>(s)], lambda[s]);
      predicted.col(spring.i) += correction.dx_i;
      predicted.col(spring.j) += correction.dx_j;
      lambda[s] += correction.dlambda;
    }
  }

  particles.v = (predicted - particles.x) / dt;
  particles.x = predicted;
}

}  // namespace cl::lab08
