#pragma once
// Lab 14 — given code: contact detection against the scene's colliders, the
// three steps with contact (PBD and XPBD from labs 04 and 08 followed by the
// contact projection with friction; lab 07's constrained step with the contact
// rows solved by projected Gauss-Seidel), and the frame loop around them,
// shared by the driver and the graded tests. The state lives here; the
// student's functions (contact.h) stay stateless.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/frame_loop.h"
#include "common/scene.h"
#include "common/sparse.h"
#include "contact.h"
#include "pbd.h"

namespace cl::lab14 {

enum class Method { kPbd, kXpbd, kConstrained };
const char* method_name(Method method);             // "pbd", "xpbd", "constrained"
Method method_from_name(const std::string& name);   // throws std::invalid_argument for another word

struct StepSettings {
  Method method = Method::kPbd;
  double dt = 1.0 / 60.0;                    // s, finite and > 0
  Eigen::Vector3d gravity{0.0, -9.81, 0.0};  // m/s²
  // pbd, xpbd: the springs' Gauss-Seidel sweeps (labs 04, 08), then as many
  // passes over the contacts (one is enough unless a particle touches two
  // colliders). constrained: block Gauss-Seidel iterations, each an exact
  // solve of the spring rows and one PGS sweep over the contact rows, in each
  // of up to 4 passes (the springs linearised anew each pass). >= 1.
  int iterations = 10;
  std::optional<double> friction;            // μ for every collider (--friction); unset: each collider's own
};

// The contacts of one step (README.md, "Detection"). For every movable
// particle i and every collider, with s(y) = surface_distance(collider, y):
//   - swept: the segment start_i -> end_i starts outside (s(start_i) >= −1e-12 m:
//     a start on the surface up to round-off counts as outside) and
//     enters the collider (the least s along it, found by ternary search since
//     s is convex along a line, is < 0): the contact is at the entry point
//     (bisection for s = 0 between the start and that least point) with the
//     normal there; `swept` is true when end_i itself lies outside the
//     collider (the discrete test at end_i alone would see no penetration);
//   - discrete: otherwise, when s(end_i) < margin: the contact is at the
//     closest surface point of end_i, q = end_i − s n.
// Either kind is dropped when its surface point lies more than 1e-9 m inside
// another collider (overlapping colliders: a buried piece of surface, whose
// half-space can face the other's; README.md, "Overlapping colliders").
// μ is `friction` when set, else the collider's. Contacts are listed by
// particle, then collider. Pinned particles have none.
std::vector<Contact> detect_contacts(const Eigen::Matrix3Xd& start, const Eigen::Matrix3Xd& end,
                                     const Eigen::VectorXd& inv_mass, const std::vector<Collider>& colliders,
                                     std::optional<double> friction, double margin);

// The deepest any movable particle lies inside any collider, m (0 when none is inside).
double max_penetration(const Eigen::Matrix3Xd& x, const Eigen::VectorXd& inv_mass,
                       const std::vector<Collider>& colliders);

// A scene that starts with particles inside colliders (contact-extremes does
// on purpose). Left there, the first step's contacts would push each out by
// its whole depth in one step, v = depth/Δt: kinetic energy from nowhere. So
// the driver moves every movable particle that starts inside a collider to
// the nearest point of its surface (x − s n, up to 8 passes over the
// colliders for overlapping ones) before frame 0, velocities untouched, and
// reports it. What it did:
struct InitialPenetration {
  int particles = 0;      // movable particles that started inside a collider (deeper than 1e-12 m)
  int worst_particle = -1;
  double deepest = 0.0;   // m, the deepest of them, before the move
  double left = 0.0;      // m, max_penetration after the move (0 unless overlapping colliders trap one)
};
InitialPenetration resolve_initial_penetration(Particles& particles, const std::vector<Collider>& colliders);

// What one step did at its contacts.
struct StepReport {
  std::vector<Contact> contacts;
  // Per contact, N: constrained, the multipliers of its rows; pbd and xpbd,
  // the force that made the projection's move over the step, λ_n = d / (w Δt²)
  // (d its normal correction) and λ_t = (friction correction) / (w Δt²), the
  // friction force: it points against the tangential move.
  std::vector<ContactMultipliers> multipliers;
  int active = 0;                 // contacts that acted: λ_n > 0 (the others were found but needed no push)
  int swept = 0;                  // contacts whose particle passed through the collider (Contact::swept)
  int sticking = 0;               // active contacts (λ_n > 0) held inside the friction cone
  int sliding = 0;                // active contacts on the cone's edge (or μ = 0)
  double max_normal_force = 0.0;  // max λ_n, N
  double normal_force = 0.0;      // Σ λ_n, N
  Eigen::Vector3d contact_force = Eigen::Vector3d::Zero();  // Σ (λ_n n + λ_t), N
  // Particles that started the step outside every collider, ended it inside
  // one (deeper than 1e-12 m) and were moved back along their step to where
  // they first touched a collider (README.md, "Detection": overlapping
  // colliders, or a collider the step's contacts did not list). 0 in a
  // scene whose colliders the contacts handle alone.
  int moved_back = 0;
  int linearizations = 0;         // constrained: the springs' rows solved at this many ends of the step (1–4)
  double unsettled = 0.0;         // m: constrained, how far the 4th pass still moved an end (0: the passes settled)
  // The step was not taken: constrained, the springs' matrix could not be
  // factored; any method, a contact function threw std::invalid_argument
  // (its message follows).
  std::string problem;
};

// One scene's stepper: the springs as labs 04/08/07 want them, the movable
// map, and the XPBD multipliers; step() advances the particles by one step.
class ContactStepper {
 public:
  // Throws std::invalid_argument for invalid settings (dt, iterations < 1, a
  // negative or non-finite friction).
  ContactStepper(const Scene& scene, const StepSettings& settings);
  // pbd / xpbd: lab 04's pbd_step or lab 08's xpbd_step (predict, the
  // springs' sweeps, v = (p − x)/Δt), then the contacts of the segment from
  // the step's start to its end (margin 0), each pass projecting every
  // contact (project_contact) and removing the tangential move it allows
  // (friction_correction), and v = (x_end − x_start)/Δt again.
  // constrained: lab 07's Schur system of the springs with the contact rows
  // (README.md): u = v + Δtg + ΔtW(J_sᵀλ_s + f_c), λ_s solved exactly for the
  // contact forces f_c, the contacts detected on x → x + Δt u of the first
  // solve (margin: the largest Δt‖u_i‖), then contact_pgs_update on each;
  // all that repeated with the springs' rows linearised again at the end the
  // last pass reached (refactored), until a pass moves no end by more than
  // 1e-5 m, at most 4 passes (StepReport::linearizations; README.md,
  // "Springs linearised at the end of the step"); then lab 07's update_positions.
  // Both: a particle that started outside every collider and ends more than
  // 1e-12 m inside one goes back along its move to where it first touches a
  // collider (StepReport::moved_back; README.md, "The last resort").
  StepReport step(Particles& particles);
  const StepSettings& settings() const { return settings_; }

 private:
  StepReport position_step(Particles& particles);
  StepReport constrained_step(Particles& particles);

  StepSettings settings_;
  std::vector<Collider> colliders_;
  std::vector<Spring> springs_;
  lab04::ConstraintSet constraints_;
  MovableMap map_;
  Eigen::VectorXd xpbd_lambda_;
  SpdFactorization schur_;  // the springs' Schur matrix: its pattern is the same every step (refactor)
  std::vector<Triplet> schur_entries_;  // its entries, refilled each time (schur_matrix)
};

// What one frame looked like (frame 0: the initial state).
struct FrameRecord {
  int frame = 0;
  double time = 0.0;            // s
  StrainStats strain;
  double kinetic = 0.0;         // J
  double potential = 0.0;       // J, gravity, zero at the origin
  double penetration = 0.0;     // max_penetration after the step, m
  StepReport report;            // the step's contacts (empty at frame 0)
  double seconds = 0.0;         // wall time of the step
  std::string problem;          // empty when healthy
};

struct RunResult {
  int steps_done = 0;
  double seconds = 0.0;
  double energy_start = 0.0;        // kinetic + potential, J
  double energy_end = 0.0;
  double max_penetration = 0.0;     // over frame 0 and every step's end, m
  double max_normal_force = 0.0;    // over every step, N
  long long contacts = 0;           // Σ over steps of the contacts found (StepReport::contacts)
  long long active = 0;             // Σ over steps of the active ones (StepReport::active)
  long long swept = 0, sticking = 0, sliding = 0;
  long long moved_back = 0;         // Σ over steps of StepReport::moved_back (particle-steps)
  long long unsettled_steps = 0;    // constrained: steps whose 4th pass still moved an end by more than 1e-5 m
  double max_unsettled = 0.0;       // m, the most such a pass moved
  std::string problem;
  int problem_step = -1;
  bool step_failed = false;
};

using FrameCallback = std::function<void(const FrameRecord&, const Particles&)>;

// Runs `steps` steps in common/frame_loop.h's loop, measuring after each and
// calling `on_frame` (if set) for frame 0 and every step. Stops at the first
// unhealthy frame (health_problem, a kinetic + potential energy rise above
// the scene's scale) or a step that could not be taken. `output`: the
// per-step CSV (step_columns()).
RunResult run_steps(Particles& particles, ContactStepper& stepper, const std::vector<Spring>& springs,
                    const std::vector<Collider>& colliders, int steps, const FrameCallback& on_frame = nullptr,
                    const FrameOutput& output = {});

// The per-step CSV's columns: contacts_found (detected, active or not),
// contacts_active (λ_n > 0), swept, sticking, sliding, moved_back (the last
// resort's particles), max_penetration (m), max_normal_force, normal_force
// (N), kinetic, potential, total_energy (J), max_strain, seconds.
std::vector<std::string> step_columns();

}  // namespace cl::lab14
