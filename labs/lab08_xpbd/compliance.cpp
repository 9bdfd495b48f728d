// Lab 08 — given code: a spring's compliance.
#include <cmath>
#include <stdexcept>
#include <string>

#include "xpbd.h"

namespace cl::lab08 {

double compliance(const Spring& spring) {
  if (!(spring.stiffness > 0.0)) {
    throw std::invalid_argument("compliance: stiffness must be > 0 (got " + std::to_string(spring.stiffness) + ")");
  }
  return std::isinf(spring.stiffness) ? 0.0 : 1.0 / spring.stiffness;
}

}  // namespace cl::lab08
