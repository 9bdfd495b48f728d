// Lab 14 — given code: detection, the three steps with contact, the frame loop.
#include "contact_step.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/health.h"
#include "common/metrics.h"
#include "step.h"
#include "xpbd.h"

namespace cl::lab14 {

const char* method_name(Method method) {
  switch (method) {
    case Method::kPbd: return "pbd";
    case Method::kXpbd: return "xpbd";
    case Method::kConstrained: return "constrained";
  }
  return "pbd";
}

Method method_from_name(const std::string& name) {
  if (name == "pbd") return Method::kPbd;
  if (name == "xpbd") return Method::kXpbd;
  if (name == "constrained") return Method::kConstrained;
  throw std::invalid_argument("method_from_name: unknown method '" + name + "' (pbd, xpbd, constrained)");
}

namespace {

constexpr double kOnSurface = 1e-12;  // m
// How deep a contact's surface point may lie inside another collider and
// still be a contact (detect_contacts): a point on the crease where two
// colliders meet is on both surfaces up to round-off (1e-16 m at the scenes'
// metre scale), far below this; any real overlap is far above it.
constexpr double kInsideOther = 1e-9;  // m
// The constrained step's re-linearisations of the springs (ContactStepper::step):
// at most this many solves of the springs' rows, stopping once a pass moves no
// particle's end of the step by more than kEndTolerance.
constexpr int kMaxLinearizations = 4;
constexpr double kEndTolerance = 1e-5;  // m

// The contact of a segment that enters a collider, or of an end point within the margin.
std::optional<Contact> contact_of(const Collider& collider, const Eigen::Vector3d& start, const Eigen::Vector3d& end,
                                  double margin) {
  const SurfacePoint at_start = surface_distance(collider, start);
  const SurfacePoint at_end = surface_distance(collider, end);
  const Eigen::Vector3d move = end - start;
  auto on_segment = [&](double t) { return surface_distance(collider, start + t * move).distance; };
  std::optional<Contact> contact;
  // s is 1-Lipschitz: a segment shorter than the start's distance cannot reach
  // the surface. A start on the surface up to round-off (a particle resting
  // there, |s| ~ 1e-17 m) counts as outside, so that its contact does not
  // switch between the two kinds with the sign of a rounding error.
  if (at_start.distance >= -kOnSurface && at_start.distance <= move.norm()) {
    double low = 0.0, high = 1.0;  // s is convex along the segment: ternary search for its least value
    for (int k = 0; k < 100 && high - low > 1e-15; ++k) {
      const double a = low + (high - low) / 3.0, b = high - (high - low) / 3.0;
      if (on_segment(a) <= on_segment(b)) high = b; else low = a;
    }
    double deepest = 0.5 * (low + high);
    if (at_end.distance < on_segment(deepest)) deepest = 1.0;
    if (on_segment(deepest) < 0.0) {
      double outside = 0.0, inside = deepest;  // bisection for the entry point
      for (int k = 0; k < 200 && inside - outside > 1e-16; ++k) {
        const double middle = 0.5 * (outside + inside);
        if (on_segment(middle) >= 0.0) outside = middle; else inside = middle;
      }
      const Eigen::Vector3d entry = start + outside * move;
      const SurfacePoint surface = surface_distance(collider, entry);
      contact = Contact{};
      contact->normal = surface.normal;
      contact->point = entry - surface.distance * surface.normal;
      contact->swept = at_end.distance >= 0.0 && at_start.distance > kOnSurface;
      return contact;
    }
  }
  if (at_end.distance < margin) {
    contact = Contact{};
    contact->normal = at_end.normal;
    contact->point = end - at_end.distance * at_end.normal;
  }
  return contact;
}

// Lab 07's Schur matrix Δt² J W Jᵀ + C, summed unknown by unknown: Δt² w_k
// J_k J_kᵀ over each unknown's three columns J_k of J (a few springs each), so
// that no sparse-sparse product is formed every step. `entries` is the
// stepper's buffer, refilled: its capacity is kept from step to step. (A new
// vector grown entry by entry at every linearisation: the draped-cloth test
// case took 3.35 s of CPU in Release against 2.45 s with the buffer, its page
// faults 72k against 9.5k; under AddressSanitizer this function was a third
// of that case, much of it the vector's growth.)
SparseMatrix schur_matrix(const lab07::LinearizedStep& lin, double dt, std::vector<Triplet>& entries) {
  const SparseMatrix& jacobian = lin.jacobian;
  entries.clear();
  std::vector<std::pair<int, Eigen::Vector3d>> rows;  // the springs at one unknown and their 3 entries
  for (Eigen::Index k = 0; 3 * k < jacobian.cols(); ++k) {
    rows.clear();
    for (int axis = 0; axis < 3; ++axis) {
      for (SparseMatrix::InnerIterator it(jacobian, 3 * k + axis); it; ++it) {
        const int row = static_cast<int>(it.row());
        auto found = std::find_if(rows.begin(), rows.end(), [row](const auto& r) { return r.first == row; });
        if (found == rows.end()) found = rows.insert(rows.end(), {row, Eigen::Vector3d::Zero()});
        found->second[axis] = it.value();
      }
    }
    const double scale = dt * dt * lin.inv_mass[3 * k];
    for (const auto& [e, je] : rows) {
      for (const auto& [f, jf] : rows) entries.emplace_back(e, f, scale * je.dot(jf));
    }
  }
  for (Eigen::Index e = 0; e < lin.compliance.size(); ++e) entries.emplace_back(e, e, lin.compliance[e]);
  for (Eigen::Index e = 0; e < jacobian.rows(); ++e) entries.emplace_back(e, e, 0.0);  // the full diagonal, always
  return assemble(jacobian.rows(), jacobian.rows(), entries);
}

void check_settings(const StepSettings& settings) {
  if (!(std::isfinite(settings.dt) && settings.dt > 0.0)) {
    throw std::invalid_argument("ContactStepper: dt must be finite and > 0 (got " + std::to_string(settings.dt) + ")");
  }
  if (settings.iterations < 1) {
    throw std::invalid_argument("ContactStepper: iterations must be >= 1 (got " +
                                std::to_string(settings.iterations) + ")");
  }
  if (!settings.gravity.allFinite()) throw std::invalid_argument("ContactStepper: gravity is not finite");
  if (settings.friction && !(std::isfinite(*settings.friction) && *settings.friction >= 0.0)) {
    throw std::invalid_argument("ContactStepper: friction must be finite and >= 0");
  }
}

// The last resort of every step (README.md, "Detection"): a movable particle
// that started the step outside every collider but ends it inside one (the
// passes or the contact sweeps moved it into a collider its contacts did not
// list, or two overlapping colliders' contacts undid each other) goes back
// along its move to the first point where it touches a collider, and its
// velocity becomes that move over Δt. Bisection on t ∈ [0, 1] keeps the
// outside end (s ≥ 0 for every collider: s is convex along the move and >= 0
// at its start, so it stays >= 0 up to its first root). Returns how many
// particles it moved.
int move_back_inside(Particles& particles, const Eigen::Matrix3Xd& start, const std::vector<Collider>& colliders,
                     double dt) {
  if (colliders.empty()) return 0;
  auto least = [&](const Eigen::Vector3d& y) {
    double s = std::numeric_limits<double>::infinity();
    for (const Collider& collider : colliders) s = std::min(s, surface_distance(collider, y).distance);
    return s;
  };
  int moved = 0;
  for (Eigen::Index i = 0; i < particles.x.cols(); ++i) {
    if (!(particles.inv_mass[i] > 0.0)) continue;
    const Eigen::Vector3d from = start.col(i), to = particles.x.col(i);
    if (least(to) >= -kOnSurface || least(from) < -kOnSurface) continue;
    double outside = 0.0, inside = 1.0;
    for (int k = 0; k < 200 && inside - outside > 1e-16; ++k) {
      const double middle = 0.5 * (outside + inside);
      if (least(from + middle * (to - from)) >= 0.0) outside = middle; else inside = middle;
    }
    particles.x.col(i) = from + outside * (to - from);
    particles.v.col(i) = (particles.x.col(i) - from) / dt;
    ++moved;
  }
  return moved;
}

// A contact acted when it pushed (λ_n > 0) or its friction moved the
// particle; the second needs the first (the cone is μ λ_n wide, and the
// position-based friction is limited by μ times the normal correction).
bool acted(const ContactMultipliers& lambda) { return lambda.normal > 0.0 || lambda.tangent.squaredNorm() > 0.0; }

void tally(StepReport& report) {
  for (std::size_t c = 0; c < report.contacts.size(); ++c) {
    const Contact& contact = report.contacts[c];
    const ContactMultipliers& lambda = report.multipliers[c];
    if (contact.swept) ++report.swept;
    if (acted(lambda)) ++report.active;
    report.max_normal_force = std::max(report.max_normal_force, lambda.normal);
    report.normal_force += lambda.normal;
    report.contact_force += lambda.normal * contact.normal + lambda.tangent;
    if (lambda.normal > 0.0) {
      const bool inside = lambda.tangent.norm() < contact.friction * lambda.normal * (1.0 - 1e-9);
      ++(inside ? report.sticking : report.sliding);
    }
  }
}

}  // namespace

std::vector<Contact> detect_contacts(const Eigen::Matrix3Xd& start, const Eigen::Matrix3Xd& end,
                                     const Eigen::VectorXd& inv_mass, const std::vector<Collider>& colliders,
                                     std::optional<double> friction, double margin) {
  std::vector<Contact> contacts;
  if (colliders.empty()) return contacts;
  for (Eigen::Index i = 0; i < end.cols(); ++i) {
    if (!(inv_mass[i] > 0.0)) continue;
    for (std::size_t c = 0; c < colliders.size(); ++c) {
      std::optional<Contact> contact = contact_of(colliders[c], start.col(i), end.col(i), margin);
      if (!contact) continue;
      // Not a contact when its surface point on this collider A lies inside
      // another, B (overlapping colliders, a sphere sunk into the floor): that
      // part of the surface is no boundary of the free space, and its
      // half-space can face the other collider's, as the bottom of the sunk
      // sphere faces the floor, so that only a far tip of their thin wedge
      // meets both (the converged constrained step threw a particle 14 m,
      // bench/README.md). The boundary the particle must reach is elsewhere,
      // and B's contact is listed: a swept entry point on A inside B lies past
      // the segment's entry into B (for a start outside B), and an end outside
      // A within the margin whose nearest point on A is inside B is nearer
      // still to B (s is 1-Lipschitz). What is left (an end inside A whose
      // nearest point on A is inside B, B beyond the margin) is the last
      // resort's when the particle started outside every collider.
      const bool inside_other = [&] {
        for (std::size_t o = 0; o < colliders.size(); ++o) {
          if (o != c && surface_distance(colliders[o], contact->point).distance < -kInsideOther) return true;
        }
        return false;
      }();
      if (inside_other) continue;
      contact->particle = static_cast<int>(i);
      contact->collider = static_cast<int>(c);
      contact->friction = friction ? *friction : colliders[c].friction;
      contacts.push_back(*contact);
    }
  }
  return contacts;
}

double max_penetration(const Eigen::Matrix3Xd& x, const Eigen::VectorXd& inv_mass,
                       const std::vector<Collider>& colliders) {
  double deepest = 0.0;
  for (const Collider& collider : colliders) {
    for (Eigen::Index i = 0; i < x.cols(); ++i) {
      if (inv_mass[i] > 0.0) deepest = std::max(deepest, -surface_distance(collider, x.col(i)).distance);
    }
  }
  return deepest;
}

InitialPenetration resolve_initial_penetration(Particles& particles, const std::vector<Collider>& colliders) {
  InitialPenetration result;
  for (Eigen::Index i = 0; i < particles.x.cols(); ++i) {
    if (!(particles.inv_mass[i] > 0.0)) continue;
    double deepest = 0.0;
    for (const Collider& collider : colliders) {
      deepest = std::max(deepest, -surface_distance(collider, particles.x.col(i)).distance);
    }
    if (deepest <= kOnSurface) continue;
    ++result.particles;
    if (deepest > result.deepest) result.deepest = deepest, result.worst_particle = static_cast<int>(i);
    for (int pass = 0; pass < 8; ++pass) {
      bool inside = false;
      for (const Collider& collider : colliders) {
        const SurfacePoint surface = surface_distance(collider, particles.x.col(i));
        if (surface.distance < 0.0) {
          particles.x.col(i) -= surface.distance * surface.normal;
          inside = true;
        }
      }
      if (!inside) break;
    }
  }
  result.left = max_penetration(particles.x, particles.inv_mass, colliders);
  return result;
}

ContactStepper::ContactStepper(const Scene& scene, const StepSettings& settings)
    : settings_(settings),
      colliders_(scene.colliders),
      springs_(scene.springs),
      constraints_(lab04::make_constraint_set(scene.particles.size(), scene.springs)),
      map_(make_movable_map(scene.particles.inv_mass)) {
  check_settings(settings_);
}

StepReport ContactStepper::step(Particles& particles) {
  // The contact functions check their arguments (contact.h); one that refuses
  // a state the step itself produced (a position gone non-finite) ends the
  // run as a step that could not be taken, naming the function, rather than
  // as a bare "invalid argument" that reads like a mistake on the command line.
  const Eigen::Matrix3Xd x = particles.x, v = particles.v;
  try {
    return settings_.method == Method::kConstrained ? constrained_step(particles) : position_step(particles);
  } catch (const std::invalid_argument& error) {
    particles.x = x, particles.v = v;
    StepReport report;
    report.problem = std::string("the step's contact code refused its input (the state it reached is not "
                                 "usable; the particles are left as the step found them): ") + error.what();
    return report;
  }
}

StepReport ContactStepper::position_step(Particles& particles) {
  const Eigen::Matrix3Xd start = particles.x;
  if (settings_.method == Method::kPbd) {
    lab04::PbdSettings pbd;
    pbd.dt = settings_.dt;
    pbd.gravity = settings_.gravity;
    pbd.iterations = settings_.iterations;
    lab04::pbd_step(particles, constraints_, pbd);
  } else {
    lab08::XpbdSettings xpbd;
    xpbd.dt = settings_.dt;
    xpbd.gravity = settings_.gravity;
    xpbd.iterations = settings_.iterations;
    lab08::xpbd_step(particles, constraints_, xpbd, xpbd_lambda_);
  }
  StepReport report;
  report.contacts = detect_contacts(start, particles.x, particles.inv_mass, colliders_, settings_.friction, 0.0);
  if (report.contacts.empty()) return report;
  report.multipliers.assign(report.contacts.size(), ContactMultipliers{});
  std::vector<int> stuck(report.contacts.size(), -1);
  const double dt2 = settings_.dt * settings_.dt;
  for (int pass = 0; pass < settings_.iterations; ++pass) {
    for (std::size_t c = 0; c < report.contacts.size(); ++c) {
      const Contact& contact = report.contacts[c];
      const double w = particles.inv_mass[contact.particle];
      auto p = particles.x.col(contact.particle);
      const ContactProjection projection = project_contact(p, w, contact.normal, contact.point);
      p += projection.dx;
      bool static_case = false;
      const Eigen::Vector3d correction = friction_correction(start.col(contact.particle), p, w, contact.normal,
                                                             projection.depth, contact.friction, static_case);
      p += correction;
      report.multipliers[c].normal += projection.depth / (w * dt2);
      report.multipliers[c].tangent += correction / (w * dt2);
      if (projection.depth > 0.0) stuck[c] = static_case ? 1 : 0;
    }
  }
  for (const Contact& contact : report.contacts) {
    particles.v.col(contact.particle) = (particles.x.col(contact.particle) - start.col(contact.particle)) / settings_.dt;
  }
  report.moved_back = move_back_inside(particles, start, colliders_, settings_.dt);
  for (std::size_t c = 0; c < report.contacts.size(); ++c) {
    if (report.contacts[c].swept) ++report.swept;
    const ContactMultipliers& lambda = report.multipliers[c];
    if (acted(lambda)) ++report.active;
    report.max_normal_force = std::max(report.max_normal_force, lambda.normal);
    report.normal_force += lambda.normal;
    report.contact_force += lambda.normal * report.contacts[c].normal + lambda.tangent;
    if (stuck[c] == 1) ++report.sticking;
    if (stuck[c] == 0) ++report.sliding;
  }
  return report;
}

StepReport ContactStepper::constrained_step(Particles& particles) {
  const double dt = settings_.dt;
  lab07::StepSettings seven;
  seven.dt = dt;
  seven.gravity = settings_.gravity;
  const int unknowns = map_.unknowns();
  Eigen::VectorXd w(3 * unknowns), free(3 * unknowns);
  for (int k = 0; k < unknowns; ++k) {
    const int p = map_.particle_of[static_cast<std::size_t>(k)];
    w.segment<3>(3 * k).setConstant(particles.inv_mass[p]);
    free.segment<3>(3 * k) = particles.v.col(p) + dt * settings_.gravity;
  }
  // The spring rows: lab 07's Schur matrix A = Δt² J W Jᵀ + C and right-hand side −φ − ΔtJ(v + Δtg).
  const bool with_springs = !springs_.empty() && unknowns > 0;
  lab07::LinearizedStep lin;
  SpdFactorization& schur = schur_;
  Eigen::VectorXd rhs;
  StepReport report;
  if (with_springs) {
    lin = lab07::linearize(particles, springs_, map_, seven);
    const SparseMatrix a = schur_matrix(lin, dt, schur_entries_);
    if (!schur.refactor(a)) {
      report.problem = "singular: the springs' Schur matrix is not positive definite (redundant hard springs?)";
      return report;
    }
    rhs = -lin.phi - dt * (lin.jacobian * free);
  }
  Eigen::VectorXd force = Eigen::VectorXd::Zero(3 * unknowns);  // contact forces J_cᵀλ_c, N
  Eigen::VectorXd velocity = free;
  // The springs' rows are linearised at the end of the step the last pass
  // reached, not only at its start (README.md, "Springs linearised at the
  // end"): lab 07's rows, linearised at x, leave a move across a spring free
  // to first order, and where a contact stops a particle within the step its
  // neighbours fall past it; the stretch that leaves, far more than any force
  // paid for, the next step's −φ turns into speed. Re-linearised at the end
  // until that end moves by less than kEndTolerance, the rows meet the
  // springs' nonlinear step (Gauss-Newton).
  Eigen::VectorXd previous_end_velocity;
  for (int pass = 0; pass < kMaxLinearizations; ++pass) {
    if (pass > 0) {
      if (!with_springs) break;
      const double moved = dt * (velocity - previous_end_velocity).cwiseAbs().maxCoeff();
      if (moved <= kEndTolerance) break;
      Particles at_end = particles;
      for (int k = 0; k < unknowns; ++k) {
        at_end.x.col(map_.particle_of[static_cast<std::size_t>(k)]) += dt * velocity.segment<3>(3 * k);
      }
      lin = lab07::linearize(at_end, springs_, map_, seven);
      if (!schur.refactor(schur_matrix(lin, dt, schur_entries_))) {
        report.problem = "singular: the springs' Schur matrix is not positive definite (redundant hard springs?)";
        return report;
      }
      // φ(y) + ΔtJ(y)(u − u_y) + Cλ = 0 about the end y = x + Δt u_y.
      rhs = -lin.phi - dt * (lin.jacobian * Eigen::VectorXd(free - velocity));
    }
    previous_end_velocity = velocity;
    ++report.linearizations;
    for (int iteration = 0; iteration < settings_.iterations; ++iteration) {
      if (with_springs) {
        const Eigen::VectorXd lambda = schur.solve(rhs - (dt * dt) * (lin.jacobian * w.cwiseProduct(force)));
        velocity = free + dt * w.cwiseProduct(Eigen::VectorXd(lin.jacobian.transpose() * lambda) + force);
      } else {
        velocity = free + dt * w.cwiseProduct(force);
      }
      if (pass == 0 && iteration == 0) {
        Eigen::Matrix3Xd end = particles.x;
        double margin = 0.0;
        for (int k = 0; k < unknowns; ++k) {
          const int p = map_.particle_of[static_cast<std::size_t>(k)];
          end.col(p) += dt * velocity.segment<3>(3 * k);
          margin = std::max(margin, dt * velocity.segment<3>(3 * k).norm());
        }
        report.contacts = detect_contacts(particles.x, end, particles.inv_mass, colliders_, settings_.friction, margin);
        report.multipliers.assign(report.contacts.size(), ContactMultipliers{});
      }
      if (report.contacts.empty()) break;
      for (std::size_t c = 0; c < report.contacts.size(); ++c) {
        const Contact& contact = report.contacts[c];
        const int k = map_.unknown_of[static_cast<std::size_t>(contact.particle)];
        Eigen::Vector3d v = velocity.segment<3>(3 * k);
        const ContactMultipliers before = report.multipliers[c];
        contact_pgs_update(particles.x.col(contact.particle), particles.inv_mass[contact.particle], dt, contact,
                           report.multipliers[c], v);
        velocity.segment<3>(3 * k) = v;
        force.segment<3>(3 * k) += (report.multipliers[c].normal - before.normal) * contact.normal +
                                   (report.multipliers[c].tangent - before.tangent);
      }
    }
  }
  if (with_springs && report.linearizations == kMaxLinearizations) {
    const double moved = dt * (velocity - previous_end_velocity).cwiseAbs().maxCoeff();
    if (moved > kEndTolerance) report.unsettled = moved;
  }
  const Eigen::Matrix3Xd start = particles.x;
  lab07::update_positions(particles, map_, velocity, dt);
  report.moved_back = move_back_inside(particles, start, colliders_, dt);
  tally(report);
  return report;
}

RunResult run_steps(Particles& particles, ContactStepper& stepper, const std::vector<Spring>& springs,
                    const std::vector<Collider>& colliders, int steps, const FrameCallback& on_frame,
                    const FrameOutput& output) {
  const StepSettings& settings = stepper.settings();
  RunResult result;
  FramePlan plan = frame_plan(steps, settings.dt, energy_scale(particles, settings.gravity, settings.dt));
  plan.energy_name = "kinetic + potential energy";
  FrameRecord record;
  StepReport last;
  auto step = [&](int) {
    last = stepper.step(particles);
    StepVerdict verdict;
    if (!last.problem.empty()) {
      verdict.problem = last.problem;
      verdict.taken = false;
    }
    return verdict;
  };
  auto measure = [&](int frame, double seconds) {
    record = FrameRecord{};
    record.frame = frame;
    record.time = frame * settings.dt;
    record.strain = strain_stats(particles.x, springs);
    record.kinetic = kinetic_energy(particles);
    record.potential = potential_energy(particles, settings.gravity);
    record.penetration = max_penetration(particles.x, particles.inv_mass, colliders);
    if (frame > 0) record.report = last;
    record.seconds = seconds;
    const StepReport& r = record.report;
    const double total = record.kinetic + record.potential;
    if (frame == 0) result.energy_start = total;
    result.energy_end = total;
    result.max_penetration = std::max(result.max_penetration, record.penetration);
    result.max_normal_force = std::max(result.max_normal_force, r.max_normal_force);
    result.contacts += static_cast<long long>(r.contacts.size());
    result.active += r.active;
    result.moved_back += r.moved_back;
    if (r.unsettled > 0.0) ++result.unsettled_steps;
    result.max_unsettled = std::max(result.max_unsettled, r.unsettled);
    result.swept += r.swept;
    result.sticking += r.sticking;
    result.sliding += r.sliding;
    FrameMeasure measured;
    measured.strain = record.strain;
    measured.energy = total;
    measured.row = {static_cast<long long>(r.contacts.size()), static_cast<long long>(r.active),
                    static_cast<long long>(r.swept), static_cast<long long>(r.sticking),
                    static_cast<long long>(r.sliding), static_cast<long long>(r.moved_back), record.penetration,
                    r.max_normal_force, r.normal_force, record.kinetic, record.potential, total, record.strain.max,
                    seconds};
    return measured;
  };
  const FrameLoopResult run = run_frame_loop(particles, step, measure, plan, output, record_hook(record, on_frame));
  copy_outcome(run, result, result.steps_done, result.problem_step);
  result.step_failed = run.step_failed;
  return result;
}

std::vector<std::string> step_columns() {
  return {"contacts_found", "contacts_active", "swept", "sticking", "sliding", "moved_back", "max_penetration",
          "max_normal_force", "normal_force", "kinetic", "potential", "total_energy", "max_strain", "seconds"};
}

}  // namespace cl::lab14
