#pragma once
// Lab 07 — given code: the driver's options, what its run and its comparison
// share (the scene's description, --stiffness, the energy and health of a
// state), and the comparison (--compare-pbd, --compare-substeps); main.cpp
// keeps the flags, the dispatch and one run's report.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/cli.h"
#include "common/particles.h"
#include "common/scene.h"

namespace cl::lab07 {

// What lab07_constrained_dynamics's own flags set (main.cpp).
struct LabOptions {
  bool stabilize = false;
  double regularize = 0.0;          // m/N on every hard constraint
  std::string stiffness;            // empty: the scene's; else a number (N/m) or "inf" for every spring
  std::vector<int> compare_pbd;     // PBD iteration counts (one substep)
  std::vector<int> compare_substeps;
};

// "NAME (P particles, S springs, H of them hard)".
std::string describe_constraints(const Scene& scene);

// --stiffness: every spring's stiffness set to a number > 0 (N/m) or "inf";
// empty leaves the scene's. Throws InputError for anything else.
void apply_stiffness(Scene& scene, const std::string& stiffness);

// The energy stored in the springs of finite stiffness (J). After a step it is
// the energy the step solved for, ½ Σ c_e λ_e² = ½ Σ λ_e²/k_e (λ = −k times the
// LINEARISED stretch); before the first step (lambda empty), ½ Σ k φ². The two
// differ by the linearisation error: on a 1e12 N/m spring a drift of 5 µm would
// count 12 J that no force ever stored (the next step treats it like a hard
// constraint's drift).
double spring_energy(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs, const Eigen::VectorXd& lambda);

// Kinetic + potential + spring_energy, J.
double total_energy(const Particles& particles, const Scene& scene, const Eigen::VectorXd& lambda);

// Empty when healthy: finite, strain below kUnstableStrain, energy not
// risen by more than the scene's scale (implicit Euler only loses energy).
std::string check_health(const Particles& particles, const Scene& scene, const Eigen::VectorXd& lambda,
                         double energy_start, double scale);

// The comparison: --scene (from scene_dir, --stiffness applied) with PBD (lab
// 04) at each --compare-pbd count and with this lab's steps at each
// --compare-substeps -> OUT/compare.csv and the table on the terminal (its
// first line naming `lab_name`). Throws InputError for --stabilize.
int run_compare(const char* lab_name, const std::string& scene_dir, const CommonOptions& options,
                const LabOptions& lab);

}  // namespace cl::lab07
