// Lab 04 — reference solution.
#include "pbd.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "gauss_seidel.h"

namespace cl::lab04 {

void pbd_step(Particles& particles, const ConstraintSet& constraints, const PbdSettings& settings) {
  const double dt = settings.dt;
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    throw std::invalid_argument("pbd_step: dt must be finite and > 0 (got " + std::to_string(dt) + ")");
  }
  if (settings.iterations < 0) {
    throw std::invalid_argument("pbd_step: iterations must be >= 0 (got " + std::to_string(settings.iterations) +
                                ")");
  }
  const Eigen::Index n = particles.size();
  if (particles.v.cols() != n || particles.inv_mass.size() != n) {
    throw std::invalid_argument("pbd_step: x, v and inv_mass disagree in size");
  }

  // Symplectic Euler for the unconstrained system; pinned particles stay put.
  // The particles are only written at the end, so a sweep that throws leaves them as they were.
  Eigen::Matrix3Xd predicted = particles.x;
  for (Eigen::Index p = 0; p < n; ++p) {
    if (particles.inv_mass[p] > 0.0) {
      const Eigen::Vector3d velocity = particles.v.col(p) + dt * settings.gravity;
      predicted.col(p) += dt * velocity;
    }
  }

  if (settings.projection == Projection::kGaussSeidel) {
    for (int k = 0; k < settings.iterations; ++k) {
      lab02::gauss_seidel_sweep(predicted, particles.inv_mass, constraints.springs, constraints.order);
    }
  } else {
    Eigen::Matrix3Xd next(3, n);
    for (int k = 0; k < settings.iterations; ++k) {
      lab03::jacobi_sweep(predicted, next, particles.inv_mass, constraints.springs, constraints.incidence,
                          settings.omega, lab03::Averaging::kByCount);
      predicted.swap(next);
    }
  }

  // The velocity is whatever moved the particle from x to its corrected
  // position (0 for a pinned particle, whose p is x).
  particles.v = (predicted - particles.x) / dt;
  particles.x = predicted;
}

}  // namespace cl::lab04
