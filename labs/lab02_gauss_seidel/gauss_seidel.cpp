// Lab 02 — your code. Read gauss_seidel.h (the contract) and README.md first.
// Grade with:  ./course grade lab02
#include "gauss_seidel.h"

#include "common/not_implemented.h"
#include "single_spring.h"

namespace cl::lab02 {

// TODO(lab02.1) [10 pts] One Gauss-Seidel sweep.
// First check the shapes: inv_mass must have one entry per column of x, and
// every index in `order` must be a valid spring index (throw
// std::invalid_argument otherwise). Then walk `order`: for each spring, call
// cl::lab01::project_distance on the CURRENT positions of its two ends and add
// the two corrections to x before moving on to the next spring, so that every
// projection sees the ones before it. Pinned particles (inverse mass 0) and
// coincident ends need nothing special: project_distance already returns zeros.
// Graded by tests/lab02_gauss_seidel/test_gauss_seidel_sweep.cpp (9 pts) and
// tests/lab02_gauss_seidel/test_stability.cpp (1 pt).
void gauss_seidel_sweep(Eigen::Matrix3Xd& x, const Eigen::VectorXd& inv_mass,
                        const std::vector<Spring>& springs, const std::vector<int>& order) {
  (void)x, (void)inv_mass, (void)springs, (void)order;
  not_implemented("gauss_seidel_sweep", __FILE__);
}

}  // namespace cl::lab02
