// Lab 04 — given code: what the sweeps need about a scene's springs.
#include <numeric>

#include "pbd.h"

namespace cl::lab04 {

ConstraintSet make_constraint_set(Eigen::Index particle_count, std::vector<Spring> springs) {
  ConstraintSet set;
  set.order.resize(springs.size());
  std::iota(set.order.begin(), set.order.end(), 0);
  set.incidence = lab03::build_incidence(particle_count, springs);
  set.springs = std::move(springs);
  return set;
}

}  // namespace cl::lab04
