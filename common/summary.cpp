#include "common/summary.h"

#include "common/output.h"

namespace cl {

namespace {
nlohmann::ordered_json columns(const Eigen::Matrix3Xd& points) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (Eigen::Index p = 0; p < points.cols(); ++p) list.push_back({points(0, p), points(1, p), points(2, p)});
  return list;
}
}  // namespace

nlohmann::ordered_json to_json(const RunSummary& summary) {
  nlohmann::ordered_json out;
  out["lab"] = summary.lab;
  out["method"] = summary.method;
  out["scene"] = summary.scene;
  if (summary.dt) out["dt"] = *summary.dt;
  if (summary.steps) out["steps"] = *summary.steps;
  if (summary.iterations) out["iterations"] = *summary.iterations;
  out["positions"] = columns(summary.positions);
  if (summary.velocities) out["velocities"] = columns(*summary.velocities);
  out["max_strain_error"] = summary.max_strain_error;
  out["seconds"] = summary.seconds;
  for (const auto& item : summary.extra.items()) out[item.key()] = item.value();
  return out;
}

void write_summary(const std::string& path, const RunSummary& summary) {
  // NaN has no JSON form; nlohmann writes null, which a reader sees as missing data.
  write_file_atomic(path, to_json(summary).dump(1) + "\n");
}

RunSummary stepping_summary(const std::string& lab, const std::string& method, const Scene& scene,
                            const Particles& state, const StrainStats& strain, double seconds) {
  RunSummary summary;
  summary.lab = lab;
  summary.method = method;
  summary.scene = scene.name;
  summary.dt = scene.dt;
  summary.steps = scene.steps;
  summary.positions = state.x;
  summary.velocities = state.v;
  summary.max_strain_error = strain.max;
  summary.seconds = seconds;
  return summary;
}

void add_energies(RunSummary& summary, double kinetic, double potential, std::optional<double> elastic,
                  double total_start) {
  summary.extra["kinetic_energy"] = kinetic;
  summary.extra["potential_energy"] = potential;
  double total = kinetic + potential;
  if (elastic) {
    summary.extra["elastic_energy"] = *elastic;
    total += *elastic;
  }
  add_total_energy(summary, total, total_start);
}

void add_total_energy(RunSummary& summary, double total, double total_start) {
  summary.extra["total_energy"] = total;
  summary.extra["total_energy_start"] = total_start;
}

void add_divergence(RunSummary& summary, const std::string& problem, const std::string& at_key, int at) {
  const bool diverged = !problem.empty();
  summary.extra["diverged"] = diverged;
  if (diverged) {
    summary.extra[at_key] = at;
    summary.extra["problem"] = problem;
  }
}

void add_stop_outcome(RunSummary& summary, const std::string& outcome, const std::string& failure, int at) {
  summary.extra["diverged"] = outcome.rfind("diverged", 0) == 0;
  summary.extra[failure] = outcome.rfind(failure, 0) == 0;
  if (!outcome.empty()) {
    summary.extra["outcome"] = outcome;
    summary.extra["stopped_at_step"] = at;
  }
}

}  // namespace cl
