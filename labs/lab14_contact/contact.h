#pragma once
// Lab 14 — contact with colliders, and Coulomb friction. The contract for the
// student's code. Derivation: labs/lab14_contact/README.md. Sources: Müller et
// al., "Position Based Dynamics" (2007), §3.3 and §3.5 (collision constraints
// generated per step, projected like any other); Macklin, Müller, Chentanez and
// Kim, "Unified Particle Physics for Real-Time Applications" (2014), §6.1,
// eqs. (24)–(25) (position-based friction); Anitescu and Potra (1997), the
// velocity-level contact step, and Erleben, "Numerical methods for linear
// complementarity problems in physics-based animation" (SIGGRAPH course,
// 2013), projected Gauss-Seidel on the Schur complement.
//
// Units: positions in m, velocities in m/s, inverse masses in 1/kg (0 =
// pinned), time in s, multipliers λ in N (lab 07's convention: the contact's
// force on the particle is Jᵀλ, so M(v_new − v)/Δt = Mg + Jᵀλ).
//
// A contact, for one step, is the half-space constraint
//     C(y) = n·(y − q) >= 0
// on the particle's position y at the END of the step: n the collider's
// outward unit normal and q a point of its surface where the particle meets
// it (the given detect_contacts in contact_step.h finds both). Colliders are
// convex, so a particle on the free side of that plane is outside the collider.
#include <Eigen/Core>

#include "common/scene.h"

namespace cl::lab14 {

// The distance from a point to a collider's surface and the outward normal there.
struct SurfacePoint {
  double distance = 0.0;                                // m: > 0 outside, 0 on the surface, < 0 inside
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();    // unit, pointing out of the collider
};

// TODO(lab14.1) — signed distance and outward normal of point x to a collider:
//   plane   (point a, unit normal n):  distance = n·(x − a),        normal = n
//   sphere  (centre a, radius r):      distance = ‖x − a‖ − r,      normal = (x − a)/‖x − a‖
//   capsule (ends a, b, radius r):     the closest point of the segment,
//       c = a + s (b − a),  s = clamp((x − a)·(b − a) / ‖b − a‖², 0, 1)   (s = 0 when a = b),
//                                      distance = ‖x − c‖ − r,      normal = (x − c)/‖x − c‖
// Degenerate input, never NaN: x at a sphere's centre or on a capsule's axis
// (‖x − a‖ = 0, ‖x − c‖ = 0) has distance −r and the normal (0, 1, 0).
// Throws std::invalid_argument for an x that is not finite.
SurfacePoint surface_distance(const Collider& collider, const Eigen::Vector3d& x);

// A contact of one particle with one collider for one step (given code:
// detect_contacts in contact_step.h fills it).
struct Contact {
  int particle = 0;
  int collider = 0;                                   // index in the scene's colliders
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();  // n, unit, out of the collider
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    // q, on the collider's surface, m
  double friction = 0.0;                              // μ >= 0
  bool swept = false;                                 // found by the swept test (the particle crossed the surface)
};

// What one contact projection did.
struct ContactProjection {
  Eigen::Vector3d dx = Eigen::Vector3d::Zero();  // the particle's correction, m
  double depth = 0.0;                            // d = −C(p) when the particle was moved, else 0 (m, >= 0)
};

// TODO(lab14.2) — the contact projection of one particle (PBD's collision
// constraint, Müller et al. 2007 §3.3): with C = n·(p − q),
//     C < 0 and w > 0:  dx = −C n,  depth = −C
//     otherwise:        dx = 0,     depth = 0
// It is lab 01's mass-weighted projection with the collider as the other end:
// the collider's inverse mass is 0, so the particle takes the whole
// correction, w/(w + 0) = 1; a pinned particle (w = 0) never moves. One-sided:
// a particle on the free side (C >= 0) is never pulled towards the collider.
// After the move, C = 0 up to round-off.
// Throws std::invalid_argument for a non-finite p or point, an inverse mass
// that is negative or not finite, or a normal that is not finite or not of
// length 1 (|‖n‖ − 1| > 1e-9).
ContactProjection project_contact(const Eigen::Vector3d& p, double inv_mass, const Eigen::Vector3d& normal,
                                  const Eigen::Vector3d& point);

// TODO(lab14.3) — position-based Coulomb friction for a particle against a
// static collider (Macklin et al. 2014, §6.1, eqs. (24)–(25), with one μ for
// static and kinetic friction and the collider's inverse mass 0). With
//     Δx_t = (I − n nᵀ)(p − x)   the particle's tangential move over the step
// (x its position at the start of the step, p its position now) and d >= 0
// the normal correction of the contact projection just done (`depth`):
//     ‖Δx_t‖ <= μ d   (static, inside the friction cone):  correction = −Δx_t
//     ‖Δx_t‖ >  μ d   (kinetic):                           correction = −Δx_t · μ d / ‖Δx_t‖
// The kinetic correction has length μ d < ‖Δx_t‖, so friction slows the
// particle and never reverses its tangential move. Zero when w = 0 (pinned),
// d = 0 or Δx_t = 0. The correction is tangential: n·correction = 0 (to
// round-off), so the contact stays met. `stuck` is set to whether the static
// case applied: w > 0, d > 0 and ‖Δx_t‖ <= μ d (true too for a particle
// pressed onto the surface with no tangential move, Δx_t = 0, whatever μ:
// with μ = 0, 0 <= 0), false otherwise (d = 0: nothing presses, so nothing
// sticks). The driver counts sticking and sliding contacts by it.
// Throws std::invalid_argument for a non-finite x, p or normal, a normal not of
// length 1 (as project_contact), a negative or non-finite inverse mass, depth
// or friction.
Eigen::Vector3d friction_correction(const Eigen::Vector3d& x, const Eigen::Vector3d& p, double inv_mass,
                                    const Eigen::Vector3d& normal, double depth, double friction, bool& stuck);

// The multipliers of one contact's rows, N: λ_n along the normal (>= 0: a
// contact pushes, never pulls) and the friction force λ_t, a vector in the
// contact's tangent plane (n·λ_t = 0), with ‖λ_t‖ <= μ λ_n (Coulomb's cone).
struct ContactMultipliers {
  double normal = 0.0;
  Eigen::Vector3d tangent = Eigen::Vector3d::Zero();
};

// TODO(lab14.4) — one projected Gauss-Seidel update of one contact's rows of
// lab 07's Schur system (Δt² J W Jᵀ + C) λ = −φ − ΔtJ(v + Δtg), contact rows
// hard (C = 0), inequality (README.md). The contact of particle i brings the
// normal row (J = nᵀ at i, φ_n = n·(x_i − q)) and two tangent rows (J = t_kᵀ,
// φ = 0, t_1, t_2 any orthonormal pair ⟂ n). `velocity` is particle i's
// v_new for the multipliers as they stand (v + Δtg + Δt w (Jᵀλ)_i, all rows);
// each row's residual there is
//     r_n = φ_n + Δt n·velocity       (the gap at the end of the step, m)
//     r_t = Δt (I − n nᵀ) velocity    (the two tangent rows as one vector, m)
// and each row's diagonal entry of Δt² J W Jᵀ is Δt² w. In this order:
//   1. normal:  λ_n' = max(0, λ_n − r_n / (Δt² w));
//               velocity += Δt w n (λ_n' − λ_n)
//   2. tangent (r_t from the updated velocity):
//               λ_t* = λ_t − r_t / (Δt² w);
//               cone: ‖λ_t*‖ > μ λ_n'  ->  λ_t* ← λ_t* · μ λ_n' / ‖λ_t*‖   (λ_t* = 0 when μ λ_n' = 0);
//               velocity += Δt w (λ_t* − λ_t)
// and `lambda` takes (λ_n', λ_t*). After it the gap r_n is >= 0 (to
// round-off) and r_n λ_n' = 0; a contact whose friction stays inside the cone
// leaves no tangential velocity. The tangent rows of one particle share its
// 3 × 3 block Δt² w I, so the two rows done at once are the same as done one
// after the other, for any t_1, t_2: the result does not depend on the basis.
// w = 0 (pinned): nothing changes.
// Throws std::invalid_argument for a dt that is not finite or <= 0, an inverse
// mass that is negative or not finite, a normal not of length 1 (as
// project_contact), a negative or non-finite friction, or non-finite x,
// point, velocity or multipliers.
void contact_pgs_update(const Eigen::Vector3d& x, double inv_mass, double dt, const Contact& contact,
                        ContactMultipliers& lambda, Eigen::Vector3d& velocity);

}  // namespace cl::lab14
