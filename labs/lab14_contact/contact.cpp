// Lab 14 — your code. Read contact.h (the contract) and README.md (the
// derivation) first. Grade with:  ./course grade lab14
#include "contact.h"

#include "common/not_implemented.h"

namespace cl::lab14 {

// TODO(lab14.1) [4 pts] The signed distance and outward normal of x to a plane,
// a sphere or a capsule (switch on collider.shape); the normal (0, 1, 0) at a
// sphere's centre or on a capsule's axis.
// Graded by tests/lab14_contact/test_surface_distance.cpp.
SurfacePoint surface_distance(const Collider& collider, const Eigen::Vector3d& x) {
  (void)collider, (void)x;
  not_implemented("surface_distance", __FILE__);
}

// TODO(lab14.2) [3 pts] C = n·(p − q); C < 0 and w > 0: dx = −C n, depth = −C;
// otherwise nothing. Graded by tests/lab14_contact/test_project_contact.cpp and
// the step cases (test_resting.cpp, test_swept.cpp, test_cloth.cpp).
ContactProjection project_contact(const Eigen::Vector3d& p, double inv_mass, const Eigen::Vector3d& normal,
                                  const Eigen::Vector3d& point) {
  (void)p, (void)inv_mass, (void)normal, (void)point;
  not_implemented("project_contact", __FILE__);
}

// TODO(lab14.3) [7 pts] Δx_t = (I − n nᵀ)(p − x); undo it inside the cone
// (‖Δx_t‖ <= μ d: stuck, also when Δx_t = 0, μ = 0 included), shorten it by μ d
// outside; nothing, and not stuck, when d = 0 or w = 0. Graded by
// tests/lab14_contact/test_friction.cpp and test_incline.cpp.
Eigen::Vector3d friction_correction(const Eigen::Vector3d& x, const Eigen::Vector3d& p, double inv_mass,
                                    const Eigen::Vector3d& normal, double depth, double friction, bool& stuck) {
  (void)x, (void)p, (void)inv_mass, (void)normal, (void)depth, (void)friction;
  stuck = false;
  not_implemented("friction_correction", __FILE__);
}

// TODO(lab14.4) [6 pts] The normal row (clamped at 0), then the two tangent
// rows as one vector (clamped to the cone μ λ_n), each moving `velocity` by
// Δt w times its change of force. Graded by tests/lab14_contact/test_pgs.cpp,
// test_resting.cpp, test_incline.cpp and test_cloth.cpp.
void contact_pgs_update(const Eigen::Vector3d& x, double inv_mass, double dt, const Contact& contact,
                        ContactMultipliers& lambda, Eigen::Vector3d& velocity) {
  (void)x, (void)inv_mass, (void)dt, (void)contact, (void)lambda, (void)velocity;
  not_implemented("contact_pgs_update", __FILE__);
}

}  // namespace cl::lab14
