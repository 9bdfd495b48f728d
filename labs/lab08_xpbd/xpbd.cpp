// Lab 08 — your code. Read xpbd.h (the contract) and README.md (the
// derivation) first. Grade with:  ./course grade lab08
#include "xpbd.h"

#include "common/not_implemented.h"

namespace cl::lab08 {

// TODO(lab08.1) [4 pts] One XPBD projection of a distance constraint.
// Check the arguments (inverse masses, rest length and alpha_tilde finite and
// >= 0, lambda finite; std::invalid_argument otherwise). With d = x_i − x_j,
// n = d/‖d‖ and C = ‖d‖ − L:
//     dlambda = (−C − alpha_tilde·lambda) / (w_i + w_j + alpha_tilde)
//     dx_i = +w_i·dlambda·n,   dx_j = −w_j·dlambda·n.
// Return all zeros when ‖d‖ = 0 or the denominator is 0.
// Graded by tests/lab08_xpbd/test_project_distance_xpbd.cpp.
XpbdCorrection project_distance_xpbd(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j, double inv_mass_i,
                                     double inv_mass_j, double rest_length, double alpha_tilde, double lambda) {
  (void)x_i, (void)x_j, (void)inv_mass_i, (void)inv_mass_j, (void)rest_length, (void)alpha_tilde, (void)lambda;
  not_implemented("project_distance_xpbd", __FILE__);
}

// TODO(lab08.2) [11 pts] One XPBD step: predict, reset λ, K sweeps, velocity update.
// Validate as xpbd.h says (dt, iterations, sizes, inverse masses finite and
// >= 0, spring and order indices, rest lengths finite and >= 0, stiffness via
// compliance(), α̃ finite) before touching anything — particles or lambda: a
// throw leaves both unchanged. Predict as in lab 04.
// Set lambda to m zeros ONCE, then run settings.iterations sweeps; in each,
// for s in constraints.order, call project_distance_xpbd on the predicted
// positions with alpha_tilde = compliance(springs[s]) / dt² and lambda[s],
// apply dx_i, dx_j and add dlambda to lambda[s]. Finish with v = (p − x)/dt, x = p.
// Graded by tests/lab08_xpbd/test_xpbd_step.cpp, test_hanging.cpp and
// test_compliant_step.cpp.
void xpbd_step(Particles& particles, const lab04::ConstraintSet& constraints, const XpbdSettings& settings,
               Eigen::VectorXd& lambda) {
  (void)particles, (void)constraints, (void)settings, (void)lambda;
  not_implemented("xpbd_step", __FILE__);
}

}  // namespace cl::lab08
