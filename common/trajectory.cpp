#include "common/trajectory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

#include <nlohmann/json.hpp>

#include "common/output.h"

namespace cl {

namespace {

std::string& stored_command_line() {
  static std::string text;
  return text;
}

// A number for the header: JSON has no NaN or inf, so those become null.
nlohmann::ordered_json number(double value) {
  return std::isfinite(value) ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr);
}

std::string megabytes(double bytes) {
  char text[32];
  if (bytes < (1 << 20)) {
    std::snprintf(text, sizeof text, "%.1f kB", bytes / 1024);
  } else {
    std::snprintf(text, sizeof text, "%.1f MB", bytes / (1 << 20));
  }
  return text;
}

}  // namespace

std::size_t trajectory_frame_bytes(std::size_t particles, std::size_t springs) {
  const std::size_t bytes = 6 * particles + springs;
  return (bytes + 3) / 4 * 4;
}

int trajectory_frames_kept(int last, int every) {
  if (last < 0 || every < 1) return 0;
  return last / every + 1;
}

void check_trajectory_size(const Scene& scene, int last, int every) {
  if (every <= 0) return;
  const double frame = static_cast<double>(
      trajectory_frame_bytes(static_cast<std::size_t>(scene.particles.size()), scene.springs.size()));
  const double bytes = frame * trajectory_frames_kept(last, every);
  if (bytes <= static_cast<double>(kTrajectoryCapBytes)) return;
  const double fitting = std::floor(static_cast<double>(kTrajectoryCapBytes) / frame);  // frames that fit
  const std::string size = "--frames " + std::to_string(every) + ": the trajectory would take " + megabytes(bytes) +
                           " (" + std::to_string(trajectory_frames_kept(last, every)) + " frames of " +
                           megabytes(frame) + "), over the " + megabytes(static_cast<double>(kTrajectoryCapBytes)) +
                           " cap";
  if (fitting < 1.0) throw InputError(size + "; even one frame does not fit");
  // floor(last / N) + 1 <= fitting  <=>  N >= floor(last / fitting) + 1
  const long long smallest = static_cast<long long>(std::floor(last / fitting)) + 1;
  throw InputError(size + "; use --frames N with a larger N (" + std::to_string(smallest) + " or more)");
}

void set_command_line(int argc, const char* const* argv) {
  std::string text;
  for (int a = 0; a < argc; ++a) {
    const std::string arg = argv[a];
    if (a > 0) text += ' ';
    const bool plain = !arg.empty() && arg.find_first_of(" \t\"'\\{}$") == std::string::npos;
    text += plain ? arg : "'" + arg + "'";
  }
  stored_command_line() = text;
}

const std::string& command_line() { return stored_command_line(); }

double signed_strain(const Eigen::Matrix3Xd& x, const Spring& spring) {
  const double length = (x.col(spring.i) - x.col(spring.j)).norm();
  return spring.rest_length > 0.0 ? (length - spring.rest_length) / spring.rest_length : length;
}

std::string colliders_json(const std::vector<Collider>& colliders) {
  using Json = nlohmann::ordered_json;
  auto point = [](const Eigen::Vector3d& p) { return Json::array({p.x(), p.y(), p.z()}); };
  Json list = Json::array();
  for (const Collider& c : colliders) {
    Json item{{"type", shape_name(c.shape)}};
    if (c.shape == ColliderShape::kPlane) {
      item["point"] = point(c.a);
      item["normal"] = point(c.normal);
    } else if (c.shape == ColliderShape::kSphere) {
      item["centre"] = point(c.a);
      item["radius"] = c.radius;
    } else {
      item["a"] = point(c.a);
      item["b"] = point(c.b);
      item["radius"] = c.radius;
    }
    item["friction"] = c.friction;
    list.push_back(item);
  }
  return list.dump();
}

TrajectoryWriter::TrajectoryWriter(const std::string& dir, int every, const Scene& scene, TrajectoryIdentity identity)
    : dir_(dir), every_(every), scene_(scene), identity_(std::move(identity)) {
  if (every < 1) {
    throw std::invalid_argument("TrajectoryWriter: every must be >= 1 (got " + std::to_string(every) + ")");
  }
}

void TrajectoryWriter::reserve(int frames) {
  if (frames <= 0) return;
  const std::size_t frame =
      trajectory_frame_bytes(static_cast<std::size_t>(scene_.particles.size()), scene_.springs.size());
  data_.reserve(std::min(kTrajectoryCapBytes, frame * static_cast<std::size_t>(frames)));
  records_.reserve(static_cast<std::size_t>(frames));
}

void TrajectoryWriter::add(int frame, double time, const Eigen::Matrix3Xd& x, double energy,
                           const std::string& status) {
  if (!x.allFinite()) {
    stopped_frame_ = frame;
    stopped_status_ = status;
    return;
  }
  const auto n = static_cast<std::size_t>(x.cols());
  const std::size_t springs = scene_.springs.size();
  Record record{frame, time, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.0, energy, status};
  if (n > 0) {
    record.box_min = x.rowwise().minCoeff();
    record.step = (x.rowwise().maxCoeff() - record.box_min) / 65535.0;
  }
  std::vector<double> strain(springs);
  for (std::size_t e = 0; e < springs; ++e) {
    strain[e] = signed_strain(x, scene_.springs[e]);
    record.strain_scale = std::max(record.strain_scale, std::abs(strain[e]));
  }

  const std::size_t start = data_.size();
  data_.resize(start + trajectory_frame_bytes(n, springs), 0);
  std::uint8_t* out = data_.data() + start;
  // Rounding to the nearest level as + 0.5 and truncation (the levels are >= 0):
  // std::round was a third of the writer's time.
  Eigen::Vector3d per_level = Eigen::Vector3d::Zero();
  for (int axis = 0; axis < 3; ++axis) {
    if (record.step[axis] > 0.0) per_level[axis] = 1.0 / record.step[axis];
  }
  for (std::size_t p = 0; p < n; ++p) {
    for (int axis = 0; axis < 3; ++axis) {
      const double level = (x(axis, static_cast<Eigen::Index>(p)) - record.box_min[axis]) * per_level[axis] + 0.5;
      const auto q = static_cast<std::uint16_t>(std::clamp(level, 0.0, 65535.0));
      *out++ = static_cast<std::uint8_t>(q & 0xffu);  // little-endian
      *out++ = static_cast<std::uint8_t>(q >> 8);
    }
  }
  const double per_strain = record.strain_scale > 0.0 ? 127.0 / record.strain_scale : 0.0;
  for (std::size_t e = 0; e < springs; ++e) {
    const double level = std::clamp(strain[e] * per_strain, -127.0, 127.0) + 127.5;  // 0.5 … 254.5
    *out++ = static_cast<std::uint8_t>(static_cast<std::int8_t>(static_cast<int>(level) - 127));
  }
  records_.push_back(std::move(record));
}

std::string TrajectoryWriter::header_text() const {
  using Json = nlohmann::ordered_json;
  const Scene& scene = scene_;
  const auto n = static_cast<std::size_t>(scene.particles.size());
  Json springs = Json::array(), rest = Json::array(), triangles = Json::array(), pinned = Json::array();
  for (const Spring& s : scene.springs) {
    springs.push_back(s.i);
    springs.push_back(s.j);
    rest.push_back(s.rest_length);
  }
  for (const Triangle& t : scene.triangles) {
    triangles.push_back(t.i);
    triangles.push_back(t.j);
    triangles.push_back(t.k);
  }
  for (Eigen::Index p = 0; p < scene.particles.inv_mass.size(); ++p) {
    if (scene.particles.inv_mass[p] == 0.0) pinned.push_back(p);
  }
  double max_error = 0.0;
  Json frames = Json::array();
  for (const Record& r : records_) {
    max_error = std::max(max_error, r.step.maxCoeff() / 2.0);
    frames.push_back(Json{{"frame", r.frame},
                          {"time", r.time},
                          {"box_min", {r.box_min.x(), r.box_min.y(), r.box_min.z()}},
                          {"step", {r.step.x(), r.step.y(), r.step.z()}},
                          {"strain_scale", r.strain_scale},
                          {"max_strain", r.strain_scale},
                          {"energy", number(r.energy)},
                          {"status", r.status}});
  }
  Json header{{"format", "cl-trajectory"},
              {"version", 1},
              {"lab", identity_.lab},
              {"scene", scene.name},
              {"method", identity_.method},
              {"command", command_line()},
              {"energy_name", identity_.energy_name},
              {"time_unit", identity_.time_unit},
              {"every", every_},
              {"particles", n},
              {"springs", springs},
              {"rest_lengths", rest},
              {"triangles", triangles},
              {"pinned", pinned},
              {"bin", "trajectory.bin"},
              {"frame_bytes", trajectory_frame_bytes(n, scene.springs.size())},
              {"bin_bytes", data_.size()},
              {"positions", "uint16 x,y,z per particle: x = box_min + q * step (per axis, per frame)"},
              {"strains", "int8 per spring after the positions: strain = q * strain_scale / 127"},
              {"max_position_error", max_error},
              {"frame_count", records_.size()},
              {"frames", frames}};
  if (!scene.colliders.empty()) header["colliders"] = Json::parse(colliders_json(scene.colliders));
  if (stopped_frame_ >= 0) header["stopped"] = Json{{"frame", stopped_frame_}, {"status", stopped_status_}};
  return header.dump() + "\n";
}

void TrajectoryWriter::finish() const {
  write_file_atomic(join_path(dir_, "trajectory.bin"),
                    std::string(reinterpret_cast<const char*>(data_.data()), data_.size()));
  write_file_atomic(join_path(dir_, "trajectory.json"), header_text());
}

}  // namespace cl
