// Lab 14 — reference solution.
#include "contact.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace cl::lab14 {

namespace {

void require_finite(const Eigen::Vector3d& value, const char* function, const char* name) {
  if (!value.allFinite()) throw std::invalid_argument(std::string(function) + ": " + name + " is not finite");
}

void require_inverse_mass(double inv_mass, const char* function) {
  if (!(std::isfinite(inv_mass) && inv_mass >= 0.0)) {
    throw std::invalid_argument(std::string(function) + ": inverse mass must be finite and >= 0 (got " +
                                std::to_string(inv_mass) + ")");
  }
}

void require_unit(const Eigen::Vector3d& normal, const char* function) {
  require_finite(normal, function, "normal");
  if (!(std::abs(normal.norm() - 1.0) <= 1e-9)) {
    throw std::invalid_argument(std::string(function) + ": the normal must have length 1 (got " +
                                std::to_string(normal.norm()) + ")");
  }
}

void require_non_negative(double value, const char* function, const char* name) {
  if (!(std::isfinite(value) && value >= 0.0)) {
    throw std::invalid_argument(std::string(function) + ": " + name + " must be finite and >= 0 (got " +
                                std::to_string(value) + ")");
  }
}

// Distance and normal from a centre point c (the sphere's, or the closest point of a capsule's axis).
SurfacePoint from_centre(const Eigen::Vector3d& x, const Eigen::Vector3d& centre, double radius) {
  const Eigen::Vector3d offset = x - centre;
  const double length = offset.norm();
  SurfacePoint result;
  result.distance = length - radius;
  if (length > 0.0) result.normal = offset / length;
  return result;
}

}  // namespace

SurfacePoint surface_distance(const Collider& collider, const Eigen::Vector3d& x) {
  require_finite(x, "surface_distance", "x");
  switch (collider.shape) {
    case ColliderShape::kPlane: {
      SurfacePoint result;
      result.distance = collider.normal.dot(x - collider.a);
      result.normal = collider.normal;
      return result;
    }
    case ColliderShape::kSphere:
      return from_centre(x, collider.a, collider.radius);
    case ColliderShape::kCapsule: {
      const Eigen::Vector3d axis = collider.b - collider.a;
      const double length2 = axis.squaredNorm();
      const double s = length2 > 0.0 ? std::clamp((x - collider.a).dot(axis) / length2, 0.0, 1.0) : 0.0;
      return from_centre(x, collider.a + s * axis, collider.radius);
    }
  }
  throw std::invalid_argument("surface_distance: unknown collider shape");
}

ContactProjection project_contact(const Eigen::Vector3d& p, double inv_mass, const Eigen::Vector3d& normal,
                                  const Eigen::Vector3d& point) {
  require_finite(p, "project_contact", "p");
  require_finite(point, "project_contact", "point");
  require_inverse_mass(inv_mass, "project_contact");
  require_unit(normal, "project_contact");
  ContactProjection result;
  const double c = normal.dot(p - point);
  if (c < 0.0 && inv_mass > 0.0) {
    result.dx = -c * normal;
    result.depth = -c;
  }
  return result;
}

Eigen::Vector3d friction_correction(const Eigen::Vector3d& x, const Eigen::Vector3d& p, double inv_mass,
                                    const Eigen::Vector3d& normal, double depth, double friction, bool& stuck) {
  stuck = false;
  require_finite(x, "friction_correction", "x");
  require_finite(p, "friction_correction", "p");
  require_unit(normal, "friction_correction");
  require_inverse_mass(inv_mass, "friction_correction");
  require_non_negative(depth, "friction_correction", "depth");
  require_non_negative(friction, "friction_correction", "friction");
  const Eigen::Vector3d move = p - x;
  const Eigen::Vector3d tangential = move - normal.dot(move) * normal;
  const double length = tangential.norm();
  if (inv_mass == 0.0 || depth == 0.0) return Eigen::Vector3d::Zero();
  const double bound = friction * depth;
  if (length <= bound) {  // with Δx_t = 0 too: pressed on, not sliding
    stuck = true;
    return -tangential;
  }
  return -tangential * (bound / length);
}

void contact_pgs_update(const Eigen::Vector3d& x, double inv_mass, double dt, const Contact& contact,
                        ContactMultipliers& lambda, Eigen::Vector3d& velocity) {
  if (!(std::isfinite(dt) && dt > 0.0)) {
    throw std::invalid_argument("contact_pgs_update: dt must be finite and > 0 (got " + std::to_string(dt) + ")");
  }
  require_inverse_mass(inv_mass, "contact_pgs_update");
  require_unit(contact.normal, "contact_pgs_update");
  require_non_negative(contact.friction, "contact_pgs_update", "friction");
  require_finite(x, "contact_pgs_update", "x");
  require_finite(contact.point, "contact_pgs_update", "point");
  require_finite(velocity, "contact_pgs_update", "velocity");
  require_finite(lambda.tangent, "contact_pgs_update", "tangent multiplier");
  if (!std::isfinite(lambda.normal)) throw std::invalid_argument("contact_pgs_update: normal multiplier is not finite");
  if (inv_mass == 0.0) return;
  const Eigen::Vector3d& n = contact.normal;
  const double diagonal = dt * dt * inv_mass;

  const double gap = n.dot(x - contact.point) + dt * n.dot(velocity);
  const double normal = std::max(0.0, lambda.normal - gap / diagonal);
  velocity += dt * inv_mass * (normal - lambda.normal) * n;

  const Eigen::Vector3d slip = dt * (velocity - n.dot(velocity) * n);
  Eigen::Vector3d tangent = lambda.tangent - slip / diagonal;
  const double bound = contact.friction * normal;
  const double length = tangent.norm();
  if (length > bound) tangent = bound > 0.0 ? Eigen::Vector3d(tangent * (bound / length)) : Eigen::Vector3d::Zero();
  velocity += dt * inv_mass * (tangent - lambda.tangent);

  lambda.normal = normal;
  lambda.tangent = tangent;
}

}  // namespace cl::lab14
