#pragma once
// The driver kit: what the labs' main.cpp do alike besides the common flags
// and run_main (common/cli.h) and the summary's shared fields
// (common/summary.h) — the scenes of a sweep, its runs shared among threads
// costliest first, an experiment's refusals, and the report's shared lines on
// the terminal (the time, where a run stopped, its energies, its multipliers).
#include <algorithm>
#include <cstddef>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/cli.h"
#include "common/frame_loop.h"
#include "common/scene.h"

namespace cl {

// The scenes a sweep runs: each name of `names` (--sweep-scenes) or, when it
// is empty, --scene alone, loaded as load_scene_for does (--dt and --steps
// applied). Throws InputError for the first that does not load (an unknown
// name of `names` blamed on --sweep-scenes).
std::vector<Scene> load_scenes(const CommonOptions& options, const std::vector<std::string>& names,
                               const std::string& lab_scene_dir);

// What a run of the frame loop writes, as every lab's driver sets it: the
// per-frame CSV OUT/csv_name (no --out: none) with `columns`, and with
// --frames N the trajectory into OUT, named by `lab`, `scene` (which must
// outlive the loop) and `method`. OBJ frames stay the lab's to ask for.
FrameOutput frame_output(const CommonOptions& options, const char* lab, const Scene& scene, const char* csv_name,
                         std::vector<std::string> columns, std::string method);

// An experiment (a sweep, a map, a comparison) writes CSV files, not one run:
// it refuses --frames with InputError("--frames: " + frames_why), then
// --summary with "--summary: " + summary_why. An empty reason lets that flag by.
void refuse_run_flags(const CommonOptions& options, const std::string& frames_why, const std::string& summary_why);

// A lab that minimises the springs' energy (labs 11, 12) takes no hard spring:
// the first spring of stiffness inf is refused with InputError
// "<source>: springs[e].stiffness: inf is a hard constraint; <why>".
void require_finite_springs(const Scene& scene, const std::string& why);

// The CSV status of a run that settles (labs 04, 08): "settled", "not
// settled", or for a run that stopped at a problem "diverged at frame F: problem".
std::string settle_status(const std::string& problem, int frame, bool settled);

// The indices 0 … n−1 of `costs`, costliest first (ties keep their order).
std::vector<std::size_t> costliest_first(const std::vector<double>& costs);

// Runs run(order[0]), run(order[1]), … shared among the OpenMP threads (when
// the caller is compiled with OpenMP; one after the other otherwise), one run
// at a time per thread, in that order. Every run is done; then the first
// exception any run threw is thrown again. Runs must not share what they write.
template <class Run>
void run_shared(const std::vector<std::size_t>& order, const Run& run) {
  std::exception_ptr failure;
  const auto count = static_cast<long>(order.size());
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 1)
#endif
  for (long k = 0; k < count; ++k) {
    try {
      run(order[static_cast<std::size_t>(k)]);
    } catch (...) {
#ifdef _OPENMP
#pragma omp critical(cl_run_shared_failure)
#endif
      if (!failure) failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
}

// The run's time on the terminal, one line:
//     "  time <seconds> s: <seconds/steps> s per <step>[, <seconds/work> s per <work_unit>]"
// (3 significant digits, e notation; the per-step figure is 0 for steps <= 0,
// the work figure only when work > 0). No line break: a lab may add to it.
void print_time(double seconds, int steps, const char* step, double work = 0.0, const char* work_unit = "");

// Where a run stopped, one line: "  <verdict> at <unit> <at> (t = <at·dt> s): <problem>"
// (verdict e.g. "DIVERGED", unit "frame" or "step", dt in s).
void print_stopped(const char* verdict, const char* unit, int at, double dt, const std::string& problem);

// The energies at the end of a run, J, one line:
//     "  <label>kinetic K J  potential P J[  elastic E J]  total T J (start S J)"
// with T = K + P (+ E); `label` is "energy:" and the spaces that align it.
void print_energies(const char* label, double kinetic, double potential, std::optional<double> elastic,
                    double total_start);

// A few multipliers, N, one line "  multipliers (N): λ0 λ1 …" when there are
// 1 to 4 of them (6 significant digits); nothing otherwise. Returns whether it printed.
bool print_multipliers(const Eigen::VectorXd& lambda);

// With --frames N, one line: "  trajectory: OUT/trajectory.{json,bin}, <frame>
// 0, N, 2N, ... and the last (./course view OUT)". Nothing without it.
void print_trajectory_note(const CommonOptions& options, const char* frame = "frame");

}  // namespace cl
