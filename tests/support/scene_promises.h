#pragma once
// What every scene the loader accepts promises the solvers (docs/DESIGN.md §3),
// checked in one place for the fuzzer (fuzz/fuzz_scene.cpp) and for the
// regression inputs it found (tests/common/test_scene_regressions.cpp).
#include <cmath>
#include <string>

#include "common/scene.h"

namespace cl::test {

// The first promise `scene` breaks, in words; empty when it keeps them all.
inline std::string broken_promise(const cl::Scene& scene) {
  const cl::Particles& particles = scene.particles;
  const Eigen::Index n = particles.size();
  if (particles.v.cols() != n || particles.inv_mass.size() != n) return "x, v and inv_mass differ in size";
  if (!particles.x.allFinite() || !particles.v.allFinite() || !particles.inv_mass.allFinite()) {
    return "a particle's x, v or inverse mass is not finite";
  }
  if ((particles.inv_mass.array() < 0.0).any()) return "a negative inverse mass";
  if (!scene.gravity.allFinite()) return "gravity is not finite";
  if (!(std::isfinite(scene.dt) && scene.dt > 0.0) || scene.steps < 0) return "dt or steps out of range";
  for (std::size_t s = 0; s < scene.springs.size(); ++s) {
    const cl::Spring& spring = scene.springs[s];
    const std::string where = "springs[" + std::to_string(s) + "]";
    if (spring.i < 0 || spring.i >= n || spring.j < 0 || spring.j >= n) return where + ": index out of range";
    if (spring.i == spring.j) return where + ": i == j";
    if (!(std::isfinite(spring.rest_length) && spring.rest_length >= 0.0)) return where + ": bad rest length";
    if (!(spring.stiffness > 0.0)) return where + ": stiffness not > 0";  // "inf" is allowed: hard
  }
  for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
    const cl::Triangle& triangle = scene.triangles[t];
    const std::string where = "triangles[" + std::to_string(t) + "]";
    for (const int index : {triangle.i, triangle.j, triangle.k}) {
      if (index < 0 || index >= n) return where + ": index out of range";
    }
    if (triangle.i == triangle.j || triangle.j == triangle.k || triangle.i == triangle.k) {
      return where + ": a repeated index";
    }
    if (!(std::isfinite(triangle.rest_area) && triangle.rest_area > 0.0)) return where + ": bad rest area";
  }
  for (std::size_t c = 0; c < scene.colliders.size(); ++c) {
    const cl::Collider& collider = scene.colliders[c];
    const std::string where = "colliders[" + std::to_string(c) + "]";
    if (!collider.a.allFinite() || !collider.b.allFinite() || !std::isfinite((collider.b - collider.a).norm())) {
      return where + ": a point or its length is not finite";
    }
    if (!(std::abs(collider.normal.norm() - 1.0) <= 1e-12)) return where + ": the normal is not a unit vector";
    if (collider.shape != cl::ColliderShape::kPlane && !(std::isfinite(collider.radius) && collider.radius > 0.0)) {
      return where + ": radius not finite and > 0";
    }
    if (!(std::isfinite(collider.friction) && collider.friction >= 0.0)) return where + ": friction not finite and >= 0";
  }
  return {};
}

}  // namespace cl::test
