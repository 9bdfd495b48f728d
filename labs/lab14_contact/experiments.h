#pragma once
// Lab 14 — given code: the driver's options and the experiments (--drape,
// --incline); main.cpp keeps the flags, the dispatch and one run's report.
#include <optional>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/scene.h"
#include "contact_step.h"

namespace cl::lab14 {

// What lab14_contact's own flags set (main.cpp).
struct LabOptions {
  std::optional<double> friction;                 // --friction: μ for every collider
  bool drape = false;                             // experiment 1
  bool incline = false;                           // experiment 2
  std::vector<std::string> frictions_given;       // --frictions as given: "0,0.3,1" (check_lab_options reads it)
  std::vector<std::string> angles_given;          // --angles as given
  std::vector<double> frictions;                  // --frictions read (empty: kFrictions)
  std::vector<double> angles;                     // --angles read, degrees (empty: kAngles)
};

// The driver's default --scene.
inline constexpr const char* kDefaultScene = "drape-sphere";

// The experiments' defaults: μ ∈ {0, 0.3, 1} (--drape, --incline), and θ in
// degrees around atan 0.3 = 16.70° and atan 1 = 45° (--incline).
inline const std::vector<double> kFrictions{0.0, 0.3, 1.0};
inline const std::vector<double> kAngles{5, 10, 15, 16, 16.5, 16.9, 17, 20, 30, 40, 44, 44.9, 45.1, 46, 50, 60};

// The largest μ a flag takes (--friction, --frictions).
inline constexpr double kMaxFriction = 1e6;

// Reads --frictions and --angles into `frictions` and `angles`. Throws
// InputError for either given without its experiment, an entry that is empty
// ("", "0.3,,1": refused, never read as 0 or skipped) or not a finite number,
// or a friction outside [0, kMaxFriction].
void check_lab_options(LabOptions& lab);

// One stderr line for a scene whose particles start inside colliders: how
// many, the deepest and which particle, and that they were moved out to the
// surface before frame 0 (no kinetic energy given to them).
void report_initial_penetration(const char* lab_name, const InitialPenetration& initial);

// The centre of mass of the movable particles (pinned ones have no mass to
// weigh), m; the origin when none moves.
Eigen::Vector3d centre_of_mass(const Particles& particles);

// How far a point moved sideways, across gravity, from `start` to `end` (m;
// the whole move when there is no gravity). For the centre of mass of a
// mirror-symmetric scene it is 0 while a run keeps the symmetry.
double sideways_drift(const Eigen::Vector3d& start, const Eigen::Vector3d& end, const Eigen::Vector3d& gravity);

// The step settings of a run: --method, --iterations, the scene's dt and
// gravity, --friction.
StepSettings step_settings(const Scene& scene, const CommonOptions& options, const LabOptions& lab);

// The incline of experiment 2 and the graded tests: one particle of mass 1 kg
// resting on a plane through the origin tilted by `degrees` about z (normal
// (−sin θ, cos θ, 0)), gravity (0, −9.81, 0), with friction μ, dt 1/60 s.
Scene incline_scene(double degrees, double friction, int steps);

// Experiment 1: the scene (--scene) with each method and each μ of
// --frictions (--iterations, --steps): the worst penetration, the final
// kinetic + potential energy, the time per step, and the time to rest (the
// first step from which the kinetic energy per kilogram stays below 1e-4
// J/kg to the end; empty when it never does) and the particle-steps the
// last resort moved back (StepReport::moved_back), and how far the centre of
// mass moved sideways (sideways_drift) -> OUT/drape.csv, a table.
int run_drape(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, const LabOptions& lab);

// Experiment 2: for each method, each μ of --frictions and each θ of
// --angles, 100 steps of incline_scene: whether the particle stuck (moved
// less than 1e-12 m along the slope), its acceleration along the slope (from
// the velocity after 100 steps) and Coulomb's g (sin θ − μ cos θ) ->
// OUT/incline.csv, and per method and μ the largest θ that sticks against
// atan μ on the terminal. Both experiments run every method (--method is not
// read); --incline refuses --scene, --steps and --dt (it builds its own).
int run_incline(const char* lab_name, const CommonOptions& options, const LabOptions& lab);

}  // namespace cl::lab14
