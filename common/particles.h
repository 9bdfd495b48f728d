#pragma once
// Particle state as the suite stores it: one column per particle.
#include <Eigen/Core>

namespace cl {

struct Particles {
  Eigen::Matrix3Xd x;         // positions (m), 3 x n
  Eigen::Matrix3Xd v;         // velocities (m/s), 3 x n
  Eigen::VectorXd inv_mass;   // 1/kg, n; 0 means pinned (infinite mass)

  Eigen::Index size() const { return x.cols(); }
};

}  // namespace cl
