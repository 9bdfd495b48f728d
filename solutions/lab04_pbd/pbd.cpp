// Lab 04 — your code. Read pbd.h (the contract) and README.md first.
// Grade with:  ./course grade lab04
#include "pbd.h"

#include "common/not_implemented.h"

namespace cl::lab04 {

// TODO(lab04.1) One PBD step: gravity into velocities, predict, K sweeps
// (lab02 or lab03), velocities from the corrected positions.
void pbd_step(Particles& particles, const ConstraintSet& constraints, const PbdSettings& settings) {
  (void)particles, (void)constraints, (void)settings;
  not_implemented("pbd_step", __FILE__);
}

}  // namespace cl::lab04
