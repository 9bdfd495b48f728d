// Lab 03 — given code: the particle-to-spring incidence, built once per scene.
#include <stdexcept>
#include <string>

#include "jacobi.h"

namespace cl::lab03 {

Incidence build_incidence(Eigen::Index particle_count, const std::vector<Spring>& springs) {
  Incidence incidence;
  const auto n = static_cast<std::size_t>(particle_count);
  incidence.offset.assign(n + 1, 0);
  for (const Spring& spring : springs) {
    if (spring.i < 0 || spring.j < 0 || static_cast<std::size_t>(spring.i) >= n ||
        static_cast<std::size_t>(spring.j) >= n) {
      throw std::invalid_argument("build_incidence: spring (" + std::to_string(spring.i) + ", " +
                                  std::to_string(spring.j) + ") outside " + std::to_string(n) + " particles");
    }
    ++incidence.offset[static_cast<std::size_t>(spring.i) + 1];
    ++incidence.offset[static_cast<std::size_t>(spring.j) + 1];
  }
  for (std::size_t p = 0; p < n; ++p) incidence.offset[p + 1] += incidence.offset[p];
  incidence.spring.resize(2 * springs.size());
  std::vector<int> next(incidence.offset.begin(), incidence.offset.end() - 1);
  for (std::size_t s = 0; s < springs.size(); ++s) {
    for (const int p : {springs[s].i, springs[s].j}) {
      incidence.spring[static_cast<std::size_t>(next[static_cast<std::size_t>(p)]++)] = static_cast<int>(s);
    }
  }
  return incidence;
}

}  // namespace cl::lab03
