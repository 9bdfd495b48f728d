#pragma once
// What every scene the loader accepts promises the solvers (docs/DESIGN.md §3),
// checked in one place for the fuzzer (fuzz/fuzz_scene.cpp) and for the
// regression inputs it found (tests/common/test_scene_regressions.cpp).
#include <cmath>
#include <string>

#include <Eigen/Core>

#include "common/scene.h"

namespace cl::test {

// Every component of `v` in `range`.
inline bool all_in(const Eigen::Ref<const Eigen::MatrixXd>& v, const cl::Range& range) {
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    if (!range.contains(v.data()[k])) return false;
  }
  return true;
}

// The first promise `scene` breaks, in words; empty when it keeps them all.
// Beyond finiteness, every number lies in its range of cl::limits
// (common/scene.h), which keeps a step's arithmetic finite.
inline std::string broken_promise(const cl::Scene& scene) {
  namespace limits = cl::limits;
  const cl::Particles& particles = scene.particles;
  const Eigen::Index n = particles.size();
  if (particles.v.cols() != n || particles.inv_mass.size() != n) return "x, v and inv_mass differ in size";
  if (!particles.x.allFinite() || !particles.v.allFinite() || !particles.inv_mass.allFinite()) {
    return "a particle's x, v or inverse mass is not finite";
  }
  if ((particles.inv_mass.array() < 0.0).any()) return "a negative inverse mass";
  if (!all_in(particles.x, limits::kCoordinate)) return "a position outside " + limits::kCoordinate.text();
  if (!all_in(particles.v, limits::kVelocity)) return "a velocity outside " + limits::kVelocity.text();
  // A cloth's mass is its total: a particle's share is down to 1/1024² of the
  // range's low end. 1/w is the mass up to round-off.
  const double side = static_cast<double>(limits::kMaxClothSide);
  const double lightest = limits::kMass.low / (side * side) * (1.0 - 1e-12);
  const double heaviest = limits::kMass.high * (1.0 + 1e-12);
  for (Eigen::Index p = 0; p < n; ++p) {
    const double w = particles.inv_mass[p];
    if (w != 0.0 && !(1.0 / w >= lightest && 1.0 / w <= heaviest)) {
      return "particle " + std::to_string(p) + ": a mass outside " + limits::kMass.text() + " (or a cloth's share of it)";
    }
  }
  if (!all_in(scene.gravity, limits::kGravity)) return "gravity outside " + limits::kGravity.text();
  if (!limits::kDt.contains(scene.dt) || scene.steps < 0 || scene.steps > limits::kMaxSteps) {
    return "dt or steps out of range";
  }
  for (std::size_t s = 0; s < scene.springs.size(); ++s) {
    const cl::Spring& spring = scene.springs[s];
    const std::string where = "springs[" + std::to_string(s) + "]";
    if (spring.i < 0 || spring.i >= n || spring.j < 0 || spring.j >= n) return where + ": index out of range";
    if (spring.i == spring.j) return where + ": i == j";
    // A rest length given is at most 1e6 m; one taken from the positions at most the box's diagonal.
    if (!(spring.rest_length >= 0.0 && spring.rest_length <= 2.0 * std::sqrt(3.0) * limits::kCoordinate.high)) {
      return where + ": bad rest length";
    }
    if (!(limits::kStiffness.contains(spring.stiffness) || spring.stiffness == cl::kInfiniteStiffness)) {
      return where + ": stiffness outside " + limits::kStiffness.text() + " and not inf";
    }
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
    if (!all_in(collider.a, limits::kCoordinate) || !all_in(collider.b, limits::kCoordinate)) {
      return where + ": a point outside " + limits::kCoordinate.text();
    }
    if (!(std::abs(collider.normal.norm() - 1.0) <= 1e-12)) return where + ": the normal is not a unit vector";
    if (collider.shape != cl::ColliderShape::kPlane && !limits::kLength.contains(collider.radius)) {
      return where + ": radius outside " + limits::kLength.text();
    }
    if (!limits::kFriction.contains(collider.friction)) return where + ": friction outside " + limits::kFriction.text();
  }
  return {};
}

}  // namespace cl::test
