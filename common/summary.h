#pragma once
// The run summary of docs/DESIGN.md §3, written by --summary.
#include <optional>
#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "common/metrics.h"
#include "common/particles.h"
#include "common/scene.h"

namespace cl {

struct RunSummary {
  std::string lab;
  std::string method;
  std::string scene;
  std::optional<double> dt;             // time-stepping labs only
  std::optional<int> steps;             // time-stepping labs only
  std::optional<int> iterations;        // iterative labs only
  Eigen::Matrix3Xd positions;           // final, scene order
  std::optional<Eigen::Matrix3Xd> velocities;  // time-stepping labs only
  double max_strain_error = 0.0;
  double seconds = 0.0;                 // wall time of the simulation part
  nlohmann::ordered_json extra = nlohmann::ordered_json::object();  // lab-specific fields
};

// The summary as JSON. Numbers are written so that they read back to the same
// double (the shortest such form, at most 17 significant digits).
nlohmann::ordered_json to_json(const RunSummary& summary);

// Writes the summary atomically. Throws InputError when the path is not writable.
void write_summary(const std::string& path, const RunSummary& summary);

// The fields every time-stepping run fills alike: lab, method, scene (its
// name), dt (s) and steps (the scene's, after --dt and --steps, also for a run
// that stopped early), positions and velocities (`state`, the final one),
// max_strain_error (strain.max) and seconds (wall time of the simulation, s).
// iterations is left unset and extra empty: the lab adds its own.
RunSummary stepping_summary(const std::string& lab, const std::string& method, const Scene& scene,
                            const Particles& state, const StrainStats& strain, double seconds);

// Appends the energies at the end of the run and its start, J, in this order:
//     kinetic_energy, potential_energy, elastic_energy (only when given),
//     total_energy (their sum: kinetic + potential + elastic), total_energy_start.
// A key the lab has set already keeps its place and takes the new value.
void add_energies(RunSummary& summary, double kinetic, double potential, std::optional<double> elastic,
                  double total_start);

// Appends total_energy and total_energy_start (J), for a lab that measures the
// total alone.
void add_total_energy(RunSummary& summary, double total, double total_start);

// Appends the verdict of a run that stops at its first problem: diverged
// (`problem` is not empty) and, only when it diverged, `at_key` (the lab's
// name for where: "diverged_at_frame" or "diverged_at_step") = at, then problem.
// An empty problem writes diverged = false alone and ignores at_key and at.
void add_divergence(RunSummary& summary, const std::string& problem, const std::string& at_key, int at);

// Appends the verdict of a run that stops at a step that diverged or could not
// be taken (labs 07, 09; `outcome` is the loop's status, empty when it ran to
// the end): diverged and `failure` (e.g. "singular"), each true when outcome
// starts with that word, and only for a run that stopped, outcome and
// stopped_at_step = at.
void add_stop_outcome(RunSummary& summary, const std::string& outcome, const std::string& failure, int at);

}  // namespace cl
