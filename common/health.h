#pragma once
// Health and energy checks shared by every time-stepping lab: a run that goes
// bad stops and says why (docs/DESIGN.md §6: never a silent NaN).
#include <string>

#include <Eigen/Core>

#include "common/metrics.h"
#include "common/particles.h"

namespace cl {

// Strain at or above this is reported as an unstable run (a spring 1000 times
// its rest length is not a cloth any more).
constexpr double kUnstableStrain = 1e3;

// Empty when the state is healthy; otherwise one line saying what went wrong:
// non-finite positions or velocities, non-finite strain, or strain >= kUnstableStrain.
std::string health_problem(const Particles& particles, const StrainStats& strain);

// The energy a scene could plausibly gain from its own start: Σ over movable
// particles of m (|g| D + ½ ‖v0‖²), D the diagonal of the initial bounding box
// (falling the scene's own size); when that is 0 (no gravity, at rest),
// Σ m ½ (D / dt)². Gravity and hard constraints can only lose energy, so a
// total energy more than this above its start means the solver is pumping
// energy in: a lab reports it as unstable. (Springs with stored elastic energy
// add it to the start; labs with springs add their own potential.)
double energy_scale(const Particles& particles, const Eigen::Vector3d& gravity, double dt);

// The verdict on an energy rise, J: `rise` is the measured energy minus its
// value at the start, `scale` the most the scene may gain (energy_scale, plus
// whatever the lab adds). Empty when rise <= scale; otherwise one line,
//     "<measured> rose <rise> J above its start (more than the scene's <scale> J): unstable"
// (both numbers to 3 significant digits). `measured` names what the lab sums
// ("total energy", "kinetic + potential energy"). scale <= 0 turns the check
// off; a NaN rise is not reported here (health_problem sees the state first).
std::string energy_rise_problem(double rise, double scale, const std::string& measured = "total energy");

}  // namespace cl
