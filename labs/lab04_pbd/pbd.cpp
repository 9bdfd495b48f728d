// Lab 04 — your code. Read pbd.h (the contract) and README.md (the derivation)
// first. Grade with:  ./course grade lab04
#include "pbd.h"

#include "common/not_implemented.h"
#include "gauss_seidel.h"  // lab02::gauss_seidel_sweep (pbd.h brings in only lab 03's jacobi.h)

namespace cl::lab04 {

// TODO(lab04.1) [15 pts] One PBD step of size settings.dt.
// Check dt (finite, > 0) and iterations (>= 0); throw std::invalid_argument
// otherwise. For every particle with inverse mass > 0 add Δt·gravity to its
// velocity and predict p = x + Δt·v; a pinned particle predicts p = x and gets
// v = 0. Then run settings.iterations sweeps on p: lab02::gauss_seidel_sweep
// in constraints.order, or lab03::jacobi_sweep with settings.omega and
// Averaging::kByCount into a second buffer that you swap with p. Finish with
// v = (p − x)/Δt and x = p. With no springs this is exactly symplectic Euler.
// Graded by tests/lab04_pbd/test_pbd_step.cpp (8 pts), test_pendulum.cpp (5 pts)
// and test_curtain.cpp (2 pts).
void pbd_step(Particles& particles, const ConstraintSet& constraints, const PbdSettings& settings) {
  (void)particles, (void)constraints, (void)settings;
  not_implemented("pbd_step", __FILE__);
}

}  // namespace cl::lab04
