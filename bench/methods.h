#pragma once
// The step of every solver of labs 04-14 behind one interface, for the two
// cross-lab programs (trade.cpp: the speed/accuracy trade; extremes.cpp: the
// stability matrix). Each wraps a lab's REFERENCE code and keeps what that
// lab's own loop keeps between steps (XPBD's multipliers, lab 09's previous
// λ, PD's factor). What each family solves is in bench/README.md.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/constraints.h"
#include "common/particles.h"
#include "common/scene.h"

namespace cl::bench {

// What a method's step converges to (bench/README.md, "Which problem"):
//   hard           PBD (GS, Jacobi, hierarchical): every spring a hard constraint;
//   implicit-euler PD, Newton, XPBD (and labs 11-13's): implicit Euler with
//                  spring energy ½ k φ² (lab 13's constrained Newton: for
//                  finite k; with hard springs it converges to the hard step);
//   linearized     KKT, Schur, Schur with geometric stiffness (lab 09): one
//                  solve of implicit Euler with the constraints linearised;
//   limited        lab 05: explicit springs and a strain limiter.
enum class Family { kHard, kImplicitEuler, kLinearized, kLimited };
const char* family_name(Family family);

struct MethodInfo {
  std::string name;   // e.g. "gs-pbd"
  std::string lab;    // e.g. "lab04"
  Family family = Family::kHard;
  bool iterative = true;   // false: a direct solve; the iteration count is not used
  bool grid_only = false;  // needs a cloth grid (the hierarchy of lab 10)
};

// Every method, in the order of the tables: gs-pbd, jacobi-pbd, hpbd, xpbd,
// pd, newton, kkt, schur, schur-kg, limit-springs, limit-triangles,
// pd-chebyshev, pd-lbfgs, jacobi-chebyshev (lab 11), vbd, vbd-chebyshev (lab 12),
// constrained-newton, constrained-newton-drop (lab 13: compressed springs
// kept in K_g, the lab's default, or dropped).
const std::vector<MethodInfo>& all_methods();
// Lab 14's three steps with contact against the scene's colliders:
// contact-pbd (lab 04's step, then the contact projection with friction),
// contact-xpbd (lab 08's), contact-constrained (lab 07's Schur step with the
// contact rows by projected Gauss-Seidel). Not in all_methods(): they are the
// extremes' contact cells. Empty in a build without lab 14's reference.
const std::vector<MethodInfo>& contact_methods();
// Whether the method steps against the scene's colliders (one of contact_methods()).
bool models_colliders(const MethodInfo& method);
// Either list's method; throws std::invalid_argument for an unknown name (the
// message lists them), and for a contact-* name in a build without lab 14's
// reference (the message says so, with kNoContactMethods).
const MethodInfo& method_info(const std::string& name);
// Why a build has no contact methods: lab 14's reference ships after its
// deadline (a student tree of week 14 has the earlier labs' only).
inline constexpr const char* kNoContactMethods =
    "solutions/lab14_contact/ ships after lab 14's deadline; the instructor's tree has it";

struct StepOutcome {
  std::string problem;  // non-empty: the lab's step said it could not be done
  int iterations = 0;   // iterations (sweeps, PD or Newton iterations) done; 1 for a direct solve
  // The linear solver behind the step: "none" for the iterative methods, or
  // the factorization (common/sparse.h's backend names, "sparse-lu", and
  // "quasi-definite-ldlt" for lab 07's KKT solve with every compliance > 0).
  std::string linear_solver = "none";
};

class Stepper {
 public:
  virtual ~Stepper() = default;
  // One step of the scene's dt from `particles` (updated in place).
  virtual StepOutcome step(Particles& particles) = 0;
};

// The method's solver for `scene`: its springs, triangles, grid, gravity and
// dt; the current positions of scene.particles are the rest shape where the
// method needs one (lab 10's hierarchy, lab 05's triangles). `iterations` is
// K (sweeps per level for hpbd; the most iterations for newton and
// constrained-newton; the PBD sweeps and contact passes, or the block
// Gauss-Seidel iterations, of the contact methods; those also take the
// scene's colliders and their friction).
// Throws std::invalid_argument or cl::InputError, with the lab's message,
// when the method does not take the scene (e.g. PD and a hard spring).
std::unique_ptr<Stepper> make_stepper(const std::string& method, const Scene& scene, int iterations);

// Σ ½ k φ² over the springs of finite stiffness (J).
double elastic_energy(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs);

}  // namespace cl::bench
