// Lab 02 — your code. Read gauss_seidel.h (the contract) and README.md first.
// Grade with:  ./course grade lab02
#include "gauss_seidel.h"

#include "common/not_implemented.h"
#include "single_spring.h"

namespace cl::lab02 {

// TODO(lab02.1) One Gauss-Seidel sweep: walk `order`, project each spring with
// cl::lab01::project_distance on the current positions and apply the two
// corrections before moving on. Check the shapes and indices first.
// Graded by tests/lab02_gauss_seidel/.
void gauss_seidel_sweep(Eigen::Matrix3Xd& x, const Eigen::VectorXd& inv_mass,
                        const std::vector<Spring>& springs, const std::vector<int>& order) {
  (void)x, (void)inv_mass, (void)springs, (void)order;
  not_implemented("gauss_seidel_sweep", __FILE__);
}

}  // namespace cl::lab02
