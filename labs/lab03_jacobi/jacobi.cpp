// Lab 03 — your code. Read jacobi.h (the contract) and README.md first.
// Grade with:  ./course grade lab03
#include "jacobi.h"

#include "common/not_implemented.h"
#include "single_spring.h"

namespace cl::lab03 {

// TODO(lab03.1) [12 pts] One Jacobi sweep.
// Before any loop: check the shapes (inv_mass and incidence.offset against the
// columns of x, incidence.spring against the springs), that ω is finite and
// >= 0, and that every inverse mass and rest length is finite and >= 0; throw
// std::invalid_argument otherwise (nothing may throw inside the parallel loop).
// Resize x_next to 3 × n (it may arrive empty or of another size). Then, for
// every particle p in an OpenMP parallel loop:
// walk p's springs in incidence order, project each with
// cl::lab01::project_distance on the OLD positions x, add up p's share of each
// correction, divide the sum by p's spring count when averaging (leave a
// particle with no springs where it is: copy its column, since x_next may be
// a reused buffer), scale by ω and write
// x_next.col(p) = x.col(p) + ω · sum / count. Each particle writes only its own
// column: no two threads touch the same memory, so no atomics, no locks, and
// the same bits for any thread count.
// Graded by tests/lab03_jacobi/test_jacobi_sweep.cpp (10 pts),
// tests/lab03_jacobi/test_parallel.cpp (1 pt: the OpenMP region) and
// tests/lab03_jacobi/test_stability.cpp (1 pt).
void jacobi_sweep(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& x_next, const Eigen::VectorXd& inv_mass,
                  const std::vector<Spring>& springs, const Incidence& incidence, double omega,
                  Averaging averaging) {
  (void)x, (void)x_next, (void)inv_mass, (void)springs, (void)incidence, (void)omega, (void)averaging;
  not_implemented("jacobi_sweep", __FILE__);
}

}  // namespace cl::lab03
