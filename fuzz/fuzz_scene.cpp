// libFuzzer target for the scene loader (docs/DESIGN.md §3): any text either
// parses into a scene that satisfies the loader's own promises or is rejected
// with cl::InputError. Any other exception, a crash, a sanitizer report or a
// scene that breaks a promise is a bug; libFuzzer keeps the input.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "common/scene.h"

namespace {

void require(bool ok) {
  if (!ok) std::abort();  // libFuzzer reports the input as a crash
}

// What every accepted scene promises to the solvers.
void check_promises(const cl::Scene& scene) {
  const cl::Particles& particles = scene.particles;
  const Eigen::Index n = particles.size();
  require(particles.v.cols() == n && particles.inv_mass.size() == n);
  require(particles.x.allFinite() && particles.v.allFinite() && particles.inv_mass.allFinite());
  require((particles.inv_mass.array() >= 0.0).all());
  require(scene.gravity.allFinite());
  require(std::isfinite(scene.dt) && scene.dt > 0.0 && scene.steps >= 0);
  for (const cl::Spring& spring : scene.springs) {
    require(spring.i >= 0 && spring.i < n && spring.j >= 0 && spring.j < n && spring.i != spring.j);
    require(std::isfinite(spring.rest_length) && spring.rest_length >= 0.0);
    require(spring.stiffness > 0.0);  // "inf" is allowed: a hard constraint
  }
  for (const cl::Triangle& triangle : scene.triangles) {
    require(triangle.i >= 0 && triangle.i < n && triangle.j >= 0 && triangle.j < n && triangle.k >= 0 &&
            triangle.k < n);
    require(triangle.i != triangle.j && triangle.j != triangle.k && triangle.i != triangle.k);
    require(std::isfinite(triangle.rest_area) && triangle.rest_area > 0.0);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    check_promises(cl::parse_scene(text, "fuzz.json"));
  } catch (const cl::InputError&) {
    // Rejected with one line naming the field: the contract.
  }
  return 0;
}
