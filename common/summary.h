#pragma once
// The run summary of docs/DESIGN.md §3, written by --summary.
#include <optional>
#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

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

}  // namespace cl
