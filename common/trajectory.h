#pragma once
// The trajectory of a run, for `./course view` (docs/DESIGN.md §3, "The
// trajectory"): OUT/trajectory.json (the run's identity, its topology and one
// record per frame kept) and OUT/trajectory.bin (per frame kept: positions
// quantised to uint16 over the frame's bounding box, strain per spring
// quantised to int8 over the frame's largest |strain|). Written whole at the
// end of the run, or not at all.
//
// The frame loop (common/frame_loop.h) writes it for every time-stepping lab;
// a sweep lab (02, 03) keeps one frame per sweep through the same writer.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/scene.h"

namespace cl {

// The most trajectory.bin may hold (bytes): a file a browser opens without trouble.
constexpr std::size_t kTrajectoryCapBytes = std::size_t{64} << 20;

// The bytes one kept frame takes in trajectory.bin: 6 per particle (x, y, z as
// uint16), 1 per spring (int8), padded to a multiple of 4.
std::size_t trajectory_frame_bytes(std::size_t particles, std::size_t springs);

// The frames 0 … last kept with every `every`-th (and `last` itself).
int trajectory_frames_kept(int last, int every);

// Throws InputError (one line: the size, the cap, and the smallest --frames N
// that fits) when every `every`-th frame of frames 0 … last of `scene` would
// make trajectory.bin larger than kTrajectoryCapBytes. every <= 0: no check.
void check_trajectory_size(const Scene& scene, int last, int every);

// The command line of this run ("prog --scene x ..."), for a trajectory's
// identity; run_main (common/cli.h) records it. Empty until set.
void set_command_line(int argc, const char* const* argv);
const std::string& command_line();

// Per-spring strain as the trajectory stores it: signed, (‖x_i − x_j‖ − L)/L
// (> 0 stretched), and for L = 0 the length ‖x_i − x_j‖ (m).
double signed_strain(const Eigen::Matrix3Xd& x, const Spring& spring);

// The scene's colliders as the trajectory's header (key "colliders", only when
// there are any) and the live page's hello carry them, for drawing: a JSON
// array, each {"type", "friction"} and plane: "point", "normal"; sphere:
// "centre", "radius"; capsule: "a", "b", "radius" (the scene file's names, m).
std::string colliders_json(const std::vector<Collider>& colliders);

struct TrajectoryIdentity {
  std::string lab;
  std::string method;
  std::string energy_name = "total energy";  // what a frame's energy sums
  std::string time_unit = "s";               // "sweep" for the sweep labs
};

class TrajectoryWriter {
 public:
  // Keeps every `every`-th frame (every >= 1) of a run on `scene` (topology:
  // its springs, triangles, pinned particles; `scene` must outlive the writer),
  // into dir/trajectory.{json,bin}. Throws std::invalid_argument for every < 1.
  TrajectoryWriter(const std::string& dir, int every, const Scene& scene, TrajectoryIdentity identity);

  // True when frame `frame` is one to keep (a multiple of every).
  bool due(int frame) const { return frame % every_ == 0; }

  // Room for `frames` frames (a hint: fewer or more may come).
  void reserve(int frames);

  // Keeps this frame (positions x, m, in scene order; energy J, NaN: unknown;
  // status "ok" or the frame's problem). A frame with a non-finite position is
  // not kept: it is the header's "stopped" record (frame and status).
  void add(int frame, double time, const Eigen::Matrix3Xd& x, double energy, const std::string& status);

  // Writes both files (atomically, trajectory.bin first). Throws InputError
  // when they cannot be written.
  void finish() const;

  int frames_kept() const { return static_cast<int>(records_.size()); }
  const std::vector<std::uint8_t>& data() const { return data_; }
  std::string header_text() const;

 private:
  struct Record {
    int frame;
    double time;
    Eigen::Vector3d box_min;
    Eigen::Vector3d step;  // m per quantisation level, per axis
    double strain_scale;   // max |strain| of the frame: q = round(127 s / scale)
    double energy;
    std::string status;
  };
  std::string dir_;
  int every_;
  const Scene& scene_;
  TrajectoryIdentity identity_;
  std::vector<Record> records_;
  std::vector<std::uint8_t> data_;
  int stopped_frame_ = -1;
  std::string stopped_status_;
};

}  // namespace cl
