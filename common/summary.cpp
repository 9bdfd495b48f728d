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

}  // namespace cl
