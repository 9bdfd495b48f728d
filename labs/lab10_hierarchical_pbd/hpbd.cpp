// Lab 10 — your code. Read hpbd.h (the contract) and README.md (the derivation)
// first. Grade with:  ./course grade lab10
#include "hpbd.h"

#include "common/not_implemented.h"

namespace cl::lab10 {

// TODO(lab10.1) [3 pts] One unilateral distance constraint C = max(0, ‖x_i − x_j‖ − L).
// If ‖x_i − x_j‖ <= L return zero corrections; otherwise return what lab01's
// project_distance returns (it also checks the arguments: call it for every
// input so that a negative inverse mass or rest length throws either way).
// Graded by tests/lab10_hierarchical_pbd/test_unilateral.cpp.
lab01::DistanceCorrection project_unilateral_distance(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j,
                                                      double inv_mass_i, double inv_mass_j, double rest_length) {
  (void)x_i, (void)x_j, (void)inv_mass_i, (void)inv_mass_j, (void)rest_length;
  not_implemented("project_unilateral_distance", __FILE__);
}

// TODO(lab10.2) [4 pts] Prolongation. Check the shapes and indices (throw
// std::invalid_argument). Then for every entry e with inv_mass[e.particle] > 0:
//     x(e.particle) += Σ_k e.weights[k] · (x(e.parents[k]) − start(e.parents[k])).
// Graded by tests/lab10_hierarchical_pbd/test_prolongation.cpp.
void prolong_corrections(Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& start,
                         const std::vector<Interpolation>& prolongation, const Eigen::VectorXd& inv_mass) {
  (void)x, (void)start, (void)prolongation, (void)inv_mass;
  not_implemented("prolong_corrections", __FILE__);
}

// TODO(lab10.3) [11 pts] The coarse-to-fine pass. Check the arguments first
// (iterations.size() == number of levels, every count >= 0, every level's
// inv_mass sized x.cols()). Keep start = x. For l = coarsest … 1: iterations[l]
// Gauss-Seidel sweeps over hierarchy.levels[l].springs (file order) with
// project_unilateral_distance and levels[l].inv_mass, then
// prolong_corrections(x, start, levels[l − 1].prolongation, levels[l − 1].inv_mass).
// Finally iterations[0] sweeps of lab02::gauss_seidel_sweep over
// levels[0].springs in file order (order 0, 1, …, m − 1) with levels[0].inv_mass.
// Graded by tests/lab10_hierarchical_pbd/test_solve.cpp (6 pts: the order, the
// start, the coarse masses, the whole pass, one level, bad arguments),
// test_at_rest.cpp (2 pts) and test_curtain.cpp (3 pts); all of them run your
// lab10.1 and lab10.2 functions too.
void solve_hierarchy(Eigen::Matrix3Xd& x, const ClothHierarchy& hierarchy, const std::vector<int>& iterations) {
  (void)x, (void)hierarchy, (void)iterations;
  not_implemented("solve_hierarchy", __FILE__);
}

}  // namespace cl::lab10
