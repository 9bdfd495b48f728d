#include "methods.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "common/hierarchy.h"
#include "common/sparse.h"
// Several labs have a simulation.h: every lab header is named by its path.
#include "labs/lab04_pbd/pbd.h"
#include "labs/lab05_strain_limiting/simulation.h"
#include "labs/lab06_projective_dynamics/simulation.h"
#include "labs/lab07_constrained_dynamics/step.h"
#include "labs/lab08_xpbd/xpbd.h"
#include "labs/lab09_stable_constrained/stable_step.h"
#include "labs/lab10_hierarchical_pbd/simulation.h"
#include "labs/lab11_acceleration/accelerated.h"
#include "labs/lab12_vertex_block_descent/descent.h"
#include "labs/lab13_constrained_newton/iteration.h"
#ifdef CL_BENCH_CONTACT
#include "labs/lab14_contact/contact_step.h"
#endif

namespace cl::bench {

const char* family_name(Family family) {
  switch (family) {
    case Family::kHard: return "hard";
    case Family::kImplicitEuler: return "implicit-euler";
    case Family::kLinearized: return "linearized";
    case Family::kLimited: return "limited";
  }
  return "?";
}

const std::vector<MethodInfo>& all_methods() {
  static const std::vector<MethodInfo> methods{
      {"gs-pbd", "lab04", Family::kHard, true, false},
      {"jacobi-pbd", "lab04", Family::kHard, true, false},
      {"hpbd", "lab10", Family::kHard, true, true},
      {"xpbd", "lab08", Family::kImplicitEuler, true, false},
      {"pd", "lab06", Family::kImplicitEuler, true, false},
      {"newton", "lab06", Family::kImplicitEuler, true, false},
      {"kkt", "lab07", Family::kLinearized, false, false},
      {"schur", "lab07", Family::kLinearized, false, false},
      {"schur-kg", "lab09", Family::kLinearized, false, false},
      {"limit-springs", "lab05", Family::kLimited, true, false},
      {"limit-triangles", "lab05", Family::kLimited, true, false},
      {"pd-chebyshev", "lab11", Family::kImplicitEuler, true, false},
      {"pd-lbfgs", "lab11", Family::kImplicitEuler, true, false},
      {"jacobi-chebyshev", "lab11", Family::kHard, true, false},
      {"vbd", "lab12", Family::kImplicitEuler, true, false},
      {"vbd-chebyshev", "lab12", Family::kImplicitEuler, true, false},
      {"constrained-newton", "lab13", Family::kImplicitEuler, true, false},
      {"constrained-newton-drop", "lab13", Family::kImplicitEuler, true, false},
  };
  return methods;
}

const std::vector<MethodInfo>& contact_methods() {
#ifdef CL_BENCH_CONTACT
  static const std::vector<MethodInfo> methods{
      {"contact-pbd", "lab14", Family::kHard, true, false},
      {"contact-xpbd", "lab14", Family::kImplicitEuler, true, false},
      {"contact-constrained", "lab14", Family::kLinearized, true, false},
  };
#else
  static const std::vector<MethodInfo> methods;
#endif
  return methods;
}

bool models_colliders(const MethodInfo& method) { return method.lab == "lab14"; }

const MethodInfo& method_info(const std::string& name) {
  for (const auto* list : {&all_methods(), &contact_methods()}) {
    for (const MethodInfo& method : *list) {
      if (method.name == name) return method;
    }
  }
  if (contact_methods().empty() && name.rfind("contact-", 0) == 0) {  // a build without lab 14's reference
    throw std::invalid_argument("'" + name + "' is lab 14's, whose reference this tree does not have (" +
                                kNoContactMethods + ")");
  }
  std::string known;
  for (const auto* list : {&all_methods(), &contact_methods()}) {
    for (const MethodInfo& method : *list) known += (known.empty() ? "" : ", ") + method.name;
  }
  throw std::invalid_argument("unknown method '" + name + "' (one of " + known + ")");
}

double elastic_energy(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  double energy = 0.0;
  for (const Spring& spring : springs) {
    if (!std::isfinite(spring.stiffness)) continue;
    const double stretch = (x.col(spring.i) - x.col(spring.j)).norm() - spring.rest_length;
    energy += 0.5 * spring.stiffness * stretch * stretch;
  }
  return energy;
}

namespace {

class PbdStepper : public Stepper {
 public:
  PbdStepper(const Scene& scene, int iterations, lab04::Projection projection)
      : constraints_(lab04::make_constraint_set(scene.particles.size(), scene.springs)) {
    settings_.dt = scene.dt;
    settings_.gravity = scene.gravity;
    settings_.iterations = iterations;
    settings_.projection = projection;
  }
  StepOutcome step(Particles& particles) override {
    lab04::pbd_step(particles, constraints_, settings_);
    return {{}, settings_.iterations};
  }

 private:
  lab04::ConstraintSet constraints_;
  lab04::PbdSettings settings_;
};

class HpbdStepper : public Stepper {
 public:
  HpbdStepper(const Scene& scene, int iterations) {
    if (scene.grid_nx < 2 || scene.grid_ny < 2) {
      throw std::invalid_argument("hpbd: the scene is not a cloth grid (lab 10 builds its hierarchy on one)");
    }
    const int levels = std::min(3, max_levels(scene.grid_nx, scene.grid_ny));
    hierarchy_ = build_cloth_hierarchy(scene.grid_nx, scene.grid_ny, scene.particles.x, scene.particles.inv_mass,
                                       scene.springs, levels);
    settings_.dt = scene.dt;
    settings_.gravity = scene.gravity;
    settings_.iterations.assign(static_cast<std::size_t>(levels), iterations);
  }
  StepOutcome step(Particles& particles) override {
    lab10::hpbd_step(particles, hierarchy_, settings_);
    return {{}, settings_.iterations.front()};
  }

 private:
  ClothHierarchy hierarchy_;
  lab10::HpbdSettings settings_;
};

class XpbdStepper : public Stepper {
 public:
  XpbdStepper(const Scene& scene, int iterations)
      : constraints_(lab04::make_constraint_set(scene.particles.size(), scene.springs)) {
    for (const Spring& spring : scene.springs) lab08::compliance(spring);  // rejects a bad stiffness now
    settings_.dt = scene.dt;
    settings_.gravity = scene.gravity;
    settings_.iterations = iterations;
  }
  StepOutcome step(Particles& particles) override {
    lab08::xpbd_step(particles, constraints_, settings_, lambda_);
    return {{}, settings_.iterations};
  }

 private:
  lab04::ConstraintSet constraints_;
  lab08::XpbdSettings settings_;
  Eigen::VectorXd lambda_;
};

// The SpdFactorization backends that factored something since `before`,
// joined by "+" ("none" if none did).
std::string backends_since(const SpdBackendCounts& before) {
  const SpdBackendCounts now = spd_backend_counts();
  std::string names;
  if (now.simplicial > before.simplicial) names = backend_name(SpdBackend::kSimplicial);
  if (now.supernodal > before.supernodal) {
    names += std::string(names.empty() ? "" : "+") + backend_name(SpdBackend::kSupernodal);
  }
  return names.empty() ? "none" : names;
}

class ImplicitEulerStepper : public Stepper {
 public:
  ImplicitEulerStepper(const Scene& scene, int iterations, lab06::Method method)
      : solver_(lab06::make_problem(scene.particles.inv_mass, scene.springs, scene.dt), method) {
    settings_.gravity = scene.gravity;
    settings_.iterations = iterations;
  }
  StepOutcome step(Particles& particles) override {
    const lab06::StepReport report = solver_.step(particles, settings_);
    return {report.problem, report.iterations_done, solver_.linear_solver()};
  }

 private:
  lab06::Solver solver_;
  lab06::StepSettings settings_;
};

class ConstrainedStepper : public Stepper {
 public:
  ConstrainedStepper(const Scene& scene, lab07::Method method)
      : springs_(scene.springs), map_(make_movable_map(scene.particles.inv_mass)) {
    const Eigen::VectorXd compliance = lab07::compliance_of(springs_);  // rejects a bad stiffness now
    settings_.dt = scene.dt;
    settings_.gravity = scene.gravity;
    settings_.method = method;
    // Lab 07's rule (constrained.h, solve_kkt): the quasi-definite LDLᵀ when
    // every c_e > 0, else the LU.
    all_compliant_ = compliance.size() == static_cast<Eigen::Index>(springs_.size()) && (compliance.array() > 0.0).all();
  }
  StepOutcome step(Particles& particles) override {
    const SpdBackendCounts before = spd_backend_counts();
    const lab07::StepResult result = lab07::constrained_step(particles, springs_, map_, settings_);
    const std::string solver = settings_.method == lab07::Method::kKkt
                                   ? std::string(all_compliant_ ? "quasi-definite-ldlt" : "sparse-lu")
                                   : backends_since(before);
    return {result.ok ? std::string() : result.problem, 1, solver};
  }

 private:
  std::vector<Spring> springs_;
  MovableMap map_;
  lab07::StepSettings settings_;
  bool all_compliant_ = false;
};

class StableStepper : public Stepper {
 public:
  explicit StableStepper(const Scene& scene)
      : springs_(scene.springs), map_(make_movable_map(scene.particles.inv_mass)) {
    lab07::compliance_of(springs_);
    settings_.step.dt = scene.dt;
    settings_.step.gravity = scene.gravity;
    settings_.step.method = lab07::Method::kSchur;
  }
  StepOutcome step(Particles& particles) override {
    const SpdBackendCounts before = spd_backend_counts();
    const lab09::StableStepResult result = lab09::stable_step(particles, springs_, map_, settings_, lambda_);
    if (!result.ok) return {result.problem, 1, backends_since(before)};
    lambda_ = result.lambda;
    return {{}, 1, backends_since(before)};
  }

 private:
  std::vector<Spring> springs_;
  MovableMap map_;
  lab09::StableSettings settings_;
  Eigen::VectorXd lambda_;
};

class LimitedStepper : public Stepper {
 public:
  LimitedStepper(const Scene& scene, int iterations, lab05::Limit limit)
      : system_(lab05::make_limited_system(scene, limit)) {
    settings_.dt = scene.dt;
    settings_.gravity = scene.gravity;
    settings_.iterations = iterations;
    settings_.limit = limit;
  }
  StepOutcome step(Particles& particles) override {
    lab05::limited_step(particles, system_, settings_);
    return {{}, settings_.iterations};
  }

 private:
  lab05::LimitedSystem system_;
  lab05::StepSettings settings_;
};

// Lab 11: PD accelerated by Chebyshev (ρ estimated once per scene from 400
// plain iterations of its first step, as the lab's driver does) or by L-BFGS
// with m = 5; Jacobi PBD by Chebyshev with γ = 0.9 (the lab's demo).
class AcceleratedStepper : public Stepper {
 public:
  AcceleratedStepper(const Scene& scene, int iterations, lab11::Method method)
      : solver_(scene.particles.inv_mass, scene.springs, scene.dt), method_(method) {
    if (lab11::minimises_objective(method)) (void)lab06::make_problem(scene.particles.inv_mass, scene.springs, scene.dt);
    settings_.gravity = scene.gravity;
    settings_.iterations = iterations;
    if (method == lab11::Method::kJacobiChebyshev) settings_.gamma = 0.9;
    if (method == lab11::Method::kPdChebyshev || method == lab11::Method::kJacobiChebyshev) {
      const std::string key = scene.name + "/" + lab11::method_name(method) + "/" +
                              std::to_string(scene.particles.size()) + "/" + std::to_string(scene.dt);
      static std::map<std::string, double> estimates;  // the trade builds a stepper per K
      auto found = estimates.find(key);
      if (found == estimates.end()) {
        const double rho = solver_.estimate_rho(scene.particles, method, settings_, 400);
        found = estimates.emplace(key, rho < 1.0 ? rho : 0.0).first;
      }
      settings_.rho = found->second;
    }
  }
  StepOutcome step(Particles& particles) override {
    const lab11::StepReport report = solver_.step(particles, method_, settings_);
    return {report.problem, report.iterations_done};
  }

 private:
  lab11::Solver solver_;
  lab11::Method method_;
  lab11::Settings settings_;
};

// Lab 12: vertex block descent with the adaptive initial guess, plain or with
// Chebyshev (ρ estimated once per scene from 400 plain sweeps of its first
// step, as the lab's driver does); the sweep runs on the program's --threads.
class VbdStepper : public Stepper {
 public:
  VbdStepper(const Scene& scene, int iterations, lab12::Method method)
      : solver_(scene.particles.inv_mass, scene.springs, scene.dt), method_(method) {
    settings_.gravity = scene.gravity;
    settings_.iterations = iterations;
    if (method == lab12::Method::kVbdChebyshev) {
      const std::string key = scene.name + "/" + std::to_string(scene.particles.size()) + "/" + std::to_string(scene.dt);
      static std::map<std::string, double> estimates;  // the trade builds a stepper per K
      auto found = estimates.find(key);
      if (found == estimates.end()) {
        const double rho = solver_.estimate_rho(scene.particles, settings_, 400);
        found = estimates.emplace(key, rho < 1.0 ? rho : 0.0).first;
      }
      settings_.rho = found->second;
    }
  }
  StepOutcome step(Particles& particles) override {
    const lab12::StepReport report = solver_.step(particles, method_, settings_);
    return {report.problem, report.iterations_done};
  }

 private:
  lab12::Solver solver_;
  lab12::Method method_;
  lab12::Settings settings_;
};

// Lab 13: Newton on the constrained system (x and λ), from the start's
// positions with λ⁰ the forces the springs carry (the previous step's λ for
// a hard spring, kept by the solver between steps, as the lab's loop keeps
// it). Tolerance 0: K iterations, as the other iterative methods run; the
// step ends earlier only at ψ = 0 or when no step length lowers the merit
// (round-off), which the trade reads as "stopped before K", as Newton's.
// Compressed springs in K_g: kept (the lab's default, the exact Jacobian;
// where the Cholesky refuses it, a part of the compression dropped, 0.01 up
// to all) for constrained-newton, dropped for constrained-newton-drop.
class ConstrainedNewtonStepper : public Stepper {
 public:
  ConstrainedNewtonStepper(const Scene& scene, int iterations, lab09::Compression compression)
      : solver_(scene.particles.inv_mass, scene.springs, scene.dt) {
    settings_.gravity = scene.gravity;
    settings_.iterations = iterations;
    settings_.tolerance = 0.0;
    settings_.start = lab13::Start::kPositions;
    settings_.warm = lab13::Warm::kForces;
    settings_.compression = compression;
  }
  StepOutcome step(Particles& particles) override {
    const SpdBackendCounts before = spd_backend_counts();
    const lab13::StepReport report = solver_.step(particles, settings_);
    // Lab 09's primal (Schur) solve when every c_e > 0 (an iteration whose
    // kept matrix is not definite drops part of the compression: the same
    // Cholesky, factored again), with
    // lab 07's KKT solve (LU) for an exact rescue; the KKT solve when some
    // spring is hard.
    std::string solver = report.linear_solver == "kkt" ? std::string("sparse-lu") : backends_since(before);
    if (report.linear_solver != "kkt" && report.exact_rescues > 0) solver += "+kkt";
    return {report.problem, report.iterations_done, solver};
  }

 private:
  lab13::Solver solver_;
  lab13::Settings settings_;
};

#ifdef CL_BENCH_CONTACT
// Lab 14: its ContactStepper with the scene's colliders (each its own μ),
// dt and gravity, K sweeps and contact passes (pbd, xpbd) or K block
// Gauss-Seidel iterations (constrained).
class ContactMethodStepper : public Stepper {
 public:
  ContactMethodStepper(const Scene& scene, int iterations, lab14::Method method)
      : stepper_(scene, settings(scene, iterations, method)) {}
  StepOutcome step(Particles& particles) override {
    const lab14::StepReport report = stepper_.step(particles);
    return {report.problem, stepper_.settings().iterations};
  }

 private:
  static lab14::StepSettings settings(const Scene& scene, int iterations, lab14::Method method) {
    lab14::StepSettings settings;
    settings.method = method;
    settings.dt = scene.dt;
    settings.gravity = scene.gravity;
    settings.iterations = iterations;
    return settings;
  }
  lab14::ContactStepper stepper_;
};
#endif

}  // namespace

std::unique_ptr<Stepper> make_stepper(const std::string& method, const Scene& scene, int iterations) {
  const std::string& name = method_info(method).name;
  if (name == "gs-pbd") return std::make_unique<PbdStepper>(scene, iterations, lab04::Projection::kGaussSeidel);
  if (name == "jacobi-pbd") return std::make_unique<PbdStepper>(scene, iterations, lab04::Projection::kJacobi);
  if (name == "hpbd") return std::make_unique<HpbdStepper>(scene, iterations);
  if (name == "xpbd") return std::make_unique<XpbdStepper>(scene, iterations);
  if (name == "pd") return std::make_unique<ImplicitEulerStepper>(scene, iterations, lab06::Method::kProjectiveDynamics);
  if (name == "newton") return std::make_unique<ImplicitEulerStepper>(scene, iterations, lab06::Method::kNewton);
  if (name == "kkt") return std::make_unique<ConstrainedStepper>(scene, lab07::Method::kKkt);
  if (name == "schur") return std::make_unique<ConstrainedStepper>(scene, lab07::Method::kSchur);
  if (name == "schur-kg") return std::make_unique<StableStepper>(scene);
  if (name == "limit-springs") return std::make_unique<LimitedStepper>(scene, iterations, lab05::Limit::kSprings);
  if (name == "pd-chebyshev") return std::make_unique<AcceleratedStepper>(scene, iterations, lab11::Method::kPdChebyshev);
  if (name == "pd-lbfgs") return std::make_unique<AcceleratedStepper>(scene, iterations, lab11::Method::kPdLbfgs);
  if (name == "vbd") return std::make_unique<VbdStepper>(scene, iterations, lab12::Method::kVbd);
  if (name == "vbd-chebyshev") return std::make_unique<VbdStepper>(scene, iterations, lab12::Method::kVbdChebyshev);
  if (name == "constrained-newton") {
    return std::make_unique<ConstrainedNewtonStepper>(scene, iterations, lab09::Compression::kKeep);
  }
  if (name == "constrained-newton-drop") {
    return std::make_unique<ConstrainedNewtonStepper>(scene, iterations, lab09::Compression::kDrop);
  }
  if (name == "jacobi-chebyshev") {
    return std::make_unique<AcceleratedStepper>(scene, iterations, lab11::Method::kJacobiChebyshev);
  }
#ifdef CL_BENCH_CONTACT
  if (name == "contact-pbd") return std::make_unique<ContactMethodStepper>(scene, iterations, lab14::Method::kPbd);
  if (name == "contact-xpbd") return std::make_unique<ContactMethodStepper>(scene, iterations, lab14::Method::kXpbd);
  if (name == "contact-constrained") {
    return std::make_unique<ContactMethodStepper>(scene, iterations, lab14::Method::kConstrained);
  }
#endif
  return std::make_unique<LimitedStepper>(scene, iterations, lab05::Limit::kTrianglesStretch);
}

}  // namespace cl::bench
