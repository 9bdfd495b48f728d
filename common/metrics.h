#pragma once
// Error and energy measures shared by every lab.
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"

namespace cl {

// Strain error of one spring: |‖x_i − x_j‖ − rest| / rest. For rest length 0
// the relative error is undefined, so the absolute length ‖x_i − x_j‖ (m) is used.
double strain_error(const Eigen::Matrix3Xd& x, const Spring& spring);

struct StrainStats {
  double max = 0.0;   // max over springs; 0 for no springs
  double rms = 0.0;   // sqrt(mean of squares); 0 for no springs
};
StrainStats strain_stats(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

// ½ Σ m ‖v‖² over particles with inverse mass > 0 (pinned particles have no
// finite kinetic energy and are skipped). J.
double kinetic_energy(const Particles& particles);

// −Σ m g·x over movable particles (J), zero at the origin.
double potential_energy(const Particles& particles, const Eigen::Vector3d& gravity);

// Σ m v over movable particles (kg m/s).
Eigen::Vector3d linear_momentum(const Particles& particles);

// True when every entry is finite.
bool all_finite(const Eigen::Matrix3Xd& values);

}  // namespace cl
