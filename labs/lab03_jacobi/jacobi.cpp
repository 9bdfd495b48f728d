// Lab 03 — your code. Read jacobi.h (the contract) and README.md first.
// Grade with:  ./course grade lab03
#include "jacobi.h"

#include "common/not_implemented.h"
#include "single_spring.h"

namespace cl::lab03 {

// TODO(lab03.1) One Jacobi sweep: for every particle p (an OpenMP parallel
// loop), sum the corrections of p's springs computed from x with
// cl::lab01::project_distance, divide by the count when averaging, scale by ω
// and write x_next.col(p). Check the shapes and ω first.
// Graded by tests/lab03_jacobi/.
void jacobi_sweep(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& x_next, const Eigen::VectorXd& inv_mass,
                  const std::vector<Spring>& springs, const Incidence& incidence, double omega,
                  Averaging averaging) {
  (void)x, (void)x_next, (void)inv_mass, (void)springs, (void)incidence, (void)omega, (void)averaging;
  not_implemented("jacobi_sweep", __FILE__);
}

}  // namespace cl::lab03
