#pragma once
// Scenes and small helpers shared by lab 14's graded tests.
#include <cmath>
#include <string>

#include "common/scene.h"
#include "contact_step.h"

namespace lab14_test {

constexpr double kG = 9.81;
constexpr double kDt = 1.0 / 60.0;
constexpr cl::lab14::Method kMethods[] = {cl::lab14::Method::kPbd, cl::lab14::Method::kXpbd,
                                          cl::lab14::Method::kConstrained};

inline cl::Collider plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, double friction = 0.0) {
  cl::Collider c;
  c.shape = cl::ColliderShape::kPlane;
  c.a = point;
  c.normal = normal.normalized();
  c.friction = friction;
  return c;
}

inline cl::Collider sphere(const Eigen::Vector3d& centre, double radius, double friction = 0.0) {
  cl::Collider c;
  c.shape = cl::ColliderShape::kSphere;
  c.a = c.b = centre;
  c.radius = radius;
  c.friction = friction;
  return c;
}

inline cl::Collider capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius, double friction = 0.0) {
  cl::Collider c;
  c.shape = cl::ColliderShape::kCapsule;
  c.a = a;
  c.b = b;
  c.radius = radius;
  c.friction = friction;
  return c;
}

// One particle of mass `mass` at x with velocity v, and the colliders.
inline cl::Scene particle(const Eigen::Vector3d& x, const Eigen::Vector3d& v, double mass = 1.0) {
  cl::Scene scene;
  scene.name = "particle";
  scene.dt = kDt;
  scene.particles.x = x;
  scene.particles.v = v;
  scene.particles.inv_mass = Eigen::VectorXd::Constant(1, 1.0 / mass);
  return scene;
}

// A side x side cloth (1 m square, 1 kg, springs of stiffness k) flat in the
// x-z plane at height y0, from the loader's generator.
inline cl::Scene flat_cloth(int side, double y0, double k) {
  cl::Scene scene = cl::parse_scene(R"({"cloth": {"nx": )" + std::to_string(side) + R"(, "ny": )" +
                                        std::to_string(side) + R"(, "plane": "xz", "mass": 1.0, "stiffness": )" +
                                        std::to_string(k) + R"(, "springs": ["structural", "shear", "bending"]}})",
                                    "cloth.json");
  scene.particles.x.row(1).setConstant(y0);
  scene.dt = kDt;
  return scene;
}

inline cl::lab14::StepSettings settings_for(cl::lab14::Method method, int iterations = 10) {
  cl::lab14::StepSettings settings;
  settings.method = method;
  settings.dt = kDt;
  settings.gravity = Eigen::Vector3d(0.0, -kG, 0.0);
  settings.iterations = iterations;
  return settings;
}

}  // namespace lab14_test
