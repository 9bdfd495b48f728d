// The extremes matrix (issue 12, docs/DESIGN.md §6): every solver of labs
// 04-13 × stiffness × Δt × mass ratio × geometry × iteration count on a small
// curtain. Each cell ends one of four ways:
//   finite          every step done, the state finite and bounded;
//   reported        the program said it went wrong: the step reported a
//                   problem or threw with a message, or the health check of
//                   common/health.h stopped the run (strain >= 1e3, energy
//                   rising more than energy_scale above its start);
//   not-applicable  the method rejects the scene with a clear error (PD and a
//                   hard spring, lab 05 and a zero rest length);
//   silent-nan      a step reported nothing yet left a non-finite state: a bug.
// Exits 1 when any cell is silent-nan. Details: bench/README.md.
//
//   extremes [--quick] [--out DIR] [--methods a,b] [--steps N] [--long-steps N]
//
// Writes DIR/extremes.csv (one row per cell) and DIR/extremes_counts.csv.
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <Eigen/Core>

#include "common/cli.h"
#include "common/csv.h"
#include "common/health.h"
#include "common/metrics.h"
#include "common/output.h"
#include "common/scene.h"
#include "common/sparse.h"
#include "common/timer.h"
#include "methods.h"

namespace {

using cl::bench::Family;

struct Options {
  bool quick = false;
  std::string out = "out/bench";
  std::vector<std::string> methods;
  int steps = 0;       // 0: 120 (quick 8)
  int long_steps = 0;  // steps of the 10,000-iteration cells; 0: 12 (quick 2)
  int threads = 1;
};

const std::vector<double> kStiffness{1e-3, 1.0, 1e6, 1e12, cl::kInfiniteStiffness};
const std::vector<double> kDt{1e-6, 1.0 / 60.0, 0.5};
const std::vector<double> kMassRatio{1.0, 1e3, 1e6};
const std::vector<std::string> kGeometry{"normal", "coincident", "zero-rest", "degenerate-triangle"};
const std::vector<int> kIterations{1, 10000};
const std::vector<std::string> kOutcomes{"finite", "reported", "not-applicable", "silent-nan"};

// A 4 × 4 curtain, 1 kg, pinned at its top corners, structural and shear
// springs and the generator's triangles: small enough for 10,000 sweeps per
// step, big enough for lab 10's two levels. Row 0 is the top.
constexpr int kN = 4;
int id(int row, int col) { return row * kN + col; }

cl::Scene base_scene() {
  return cl::parse_scene(R"({"name": "extremes-curtain-4", "cloth": {"nx": 4, "ny": 4, "width": 1, "height": 1,
      "mass": 1, "pin": ["top-left", "top-right"], "springs": ["structural", "shear"]}})",
                         "extremes scene");
}

std::string stiffness_text(double k) { return std::isfinite(k) ? cl::format_double(k) : std::string("inf"); }

// The scene of one cell: the solver sees these springs, masses and Δt; the
// geometry's change of the positions comes after the solver is built (so that
// a rest shape, lab 05's triangles or lab 10's hierarchy, stays the curtain's).
cl::Scene cell_scene(const cl::Scene& base, double stiffness, double dt, double mass_ratio, const std::string& geometry) {
  cl::Scene scene = base;
  scene.dt = dt;
  for (cl::Spring& spring : scene.springs) {
    spring.stiffness = stiffness;
    if (geometry == "zero-rest") spring.rest_length = 0.0;
  }
  for (int col = 0; col < kN; ++col) scene.particles.inv_mass[id(kN - 1, col)] /= mass_ratio;  // a heavy hem
  return scene;
}

void deform(cl::Particles& particles, const std::string& geometry) {
  if (geometry == "coincident") {
    particles.x.col(id(1, 1)) = particles.x.col(id(1, 2));  // two neighbours on one point
  } else if (geometry == "degenerate-triangle") {
    // Triangle (0,1), (1,0), (1,1) of the generator: (1,1) onto the middle of
    // the opposite edge, zero area.
    particles.x.col(id(1, 1)) = 0.5 * (particles.x.col(id(0, 1)) + particles.x.col(id(1, 0)));
  }
}

struct Cell {
  std::string method, geometry, outcome, message;
  double stiffness = 0, dt = 0, mass_ratio = 0, max_strain = 0, seconds = 0;
  int iterations = 0, steps = 0, steps_done = 0;
};

double energy(const cl::Particles& particles, const cl::Scene& scene, bool elastic) {
  double e = cl::kinetic_energy(particles) + cl::potential_energy(particles, scene.gravity);
  if (elastic) e += cl::bench::elastic_energy(particles.x, scene.springs);
  return e;
}

Cell run_cell(const cl::Scene& base, const cl::bench::MethodInfo& method, double stiffness, double dt,
              double mass_ratio, const std::string& geometry, int iterations, int steps) {
  Cell cell{method.name, geometry, "", "", stiffness, dt, mass_ratio, 0.0, 0.0, iterations, steps, 0};
  const cl::Timer timer;
  const cl::Scene scene = cell_scene(base, stiffness, dt, mass_ratio, geometry);
  std::unique_ptr<cl::bench::Stepper> stepper;
  try {
    stepper = cl::bench::make_stepper(method.name, scene, iterations);
  } catch (const std::exception& error) {  // std::invalid_argument or cl::InputError, with the lab's message
    cell.outcome = "not-applicable";
    cell.message = error.what();
    return cell;
  }
  cl::Particles state = scene.particles;
  deform(state, geometry);

  // The energy check of the method's own lab: lab 04 and lab 08 count kinetic
  // and gravity only, lab 06, 07 and 09 the springs too; lab 05 checks no
  // energy when limiting (its springs may store far more, bounded by the band).
  const bool check_energy = method.family != Family::kLimited;
  const bool elastic = method.family == Family::kImplicitEuler ? method.name != "xpbd"
                                                                : method.family == Family::kLinearized;
  const double e0 = energy(state, scene, elastic);
  const double allowance = cl::energy_scale(state, scene.gravity, dt) +
                           (elastic ? 0.0 : cl::bench::elastic_energy(state.x, scene.springs));
  for (int step = 1; step <= steps; ++step) {
    const std::string at = "step " + std::to_string(step) + ": ";
    cl::bench::StepOutcome outcome;
    try {
      outcome = stepper->step(state);
    } catch (const std::exception& error) {
      cell.outcome = "reported";
      cell.message = at + "threw: " + error.what();
      break;
    }
    if (!outcome.problem.empty()) {
      cell.outcome = "reported";
      cell.message = at + outcome.problem;
      break;
    }
    if (!cl::all_finite(state.x) || !cl::all_finite(state.v)) {
      cell.outcome = "silent-nan";
      cell.message = at + "non-finite state after a step that reported nothing";
      break;
    }
    const cl::StrainStats strain = cl::strain_stats(state.x, scene.springs);
    cell.max_strain = strain.max;
    std::string trouble = cl::health_problem(state, strain);
    if (trouble.empty() && check_energy) {
      const double rise = energy(state, scene, elastic) - e0;
      if (rise > allowance) {
        char text[128];
        std::snprintf(text, sizeof text, "energy rose %.3g J above its start, more than %.3g J: unstable", rise,
                      allowance);
        trouble = text;
      }
    }
    if (!trouble.empty()) {
      cell.outcome = "reported";
      cell.message = at + trouble;
      break;
    }
    cell.steps_done = step;
  }
  if (cell.outcome.empty()) cell.outcome = "finite";
  cell.seconds = timer.seconds();
  return cell;
}

// The CSV cell text (common/csv.h does not quote): one line, no commas.
std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
    if (c == ',') c = ';';
  }
  return text;
}

int run(const Options& options) {
  std::vector<const cl::bench::MethodInfo*> methods;
  if (options.methods.empty()) {
    for (const cl::bench::MethodInfo& method : cl::bench::all_methods()) methods.push_back(&method);
  } else {
    for (const std::string& name : options.methods) {
      try {
        methods.push_back(&cl::bench::method_info(name));
      } catch (const std::invalid_argument& error) {
        throw cl::InputError(std::string("--methods: ") + error.what());
      }
    }
  }
  const int steps = options.steps > 0 ? options.steps : (options.quick ? 8 : 120);
  const int long_steps = options.long_steps > 0 ? options.long_steps : (options.quick ? 2 : 12);
  cl::ensure_directory(options.out);
#ifdef _OPENMP
  omp_set_num_threads(options.threads);
  cl::set_blas_threads(options.threads);  // CHOLMOD's BLAS too: serial methods, timed side by side
#endif
  const cl::Scene base = base_scene();
  const std::size_t per_method = kStiffness.size() * kDt.size() * kMassRatio.size() * kGeometry.size() * kIterations.size();
  std::printf("extremes: %zu methods x %zu cells on a %dx%d curtain; %d steps (%d with 10,000 iterations)\n",
              methods.size(), per_method, kN, kN, steps, long_steps);
  std::fflush(stdout);

  const bool tty = isatty(fileno(stderr)) != 0;
  const cl::Timer total;
  std::vector<Cell> cells;
  std::map<std::string, std::map<std::string, int>> counts;
  for (const cl::bench::MethodInfo* method : methods) {
    const cl::Timer method_timer;
    for (const int iterations : kIterations) {
      for (const std::string& geometry : kGeometry) {
        for (const double stiffness : kStiffness) {
          for (const double dt : kDt) {
            for (const double ratio : kMassRatio) {
              if (tty) {
                std::fprintf(stderr, "\r\033[K[%zu cells, %.0f s] %s K=%d %s k=%s dt=%g ratio=%g", cells.size(),
                             total.seconds(), method->name.c_str(), iterations, geometry.c_str(),
                             stiffness_text(stiffness).c_str(), dt, ratio);
                std::fflush(stderr);
              }
              cells.push_back(run_cell(base, *method, stiffness, dt, ratio, geometry, iterations,
                                       iterations > 1 ? long_steps : steps));
              ++counts[method->name][cells.back().outcome];
            }
          }
        }
      }
    }
    if (tty) std::fprintf(stderr, "\r\033[K");
    std::map<std::string, int>& c = counts[method->name];
    std::printf("%-23s finite %3d  reported %3d  not applicable %3d  silent NaN %3d  (%.1f s)\n", method->name.c_str(),
                c["finite"], c["reported"], c["not-applicable"], c["silent-nan"], method_timer.seconds());
    std::fflush(stdout);
  }

  cl::CsvTable table({"method", "family", "stiffness", "dt", "mass_ratio", "geometry", "iterations", "steps",
                      "steps_done", "outcome", "max_strain", "seconds", "message"});
  for (const Cell& cell : cells) {
    table.add_row({cell.method, std::string(cl::bench::family_name(cl::bench::method_info(cell.method).family)),
                   stiffness_text(cell.stiffness), cell.dt, cell.mass_ratio, cell.geometry,
                   static_cast<long long>(cell.iterations), static_cast<long long>(cell.steps),
                   static_cast<long long>(cell.steps_done), cell.outcome, cell.max_strain, cell.seconds,
                   one_line(cell.message)});
  }
  table.write(cl::join_path(options.out, "extremes.csv"));
  cl::CsvTable count_table({"method", "finite", "reported", "not_applicable", "silent_nan"});
  std::map<std::string, int> totals;
  for (const cl::bench::MethodInfo* method : methods) {
    std::map<std::string, int>& c = counts[method->name];
    count_table.add_row({method->name, static_cast<long long>(c["finite"]), static_cast<long long>(c["reported"]),
                         static_cast<long long>(c["not-applicable"]), static_cast<long long>(c["silent-nan"])});
    for (const std::string& outcome : kOutcomes) totals[outcome] += c[outcome];
  }
  count_table.add_row({std::string("total"), static_cast<long long>(totals["finite"]),
                       static_cast<long long>(totals["reported"]), static_cast<long long>(totals["not-applicable"]),
                       static_cast<long long>(totals["silent-nan"])});
  count_table.write(cl::join_path(options.out, "extremes_counts.csv"));

  std::printf("\nextremes: %zu cells in %.0f s; CSV in %s\n", cells.size(), total.seconds(), options.out.c_str());
  std::printf("finite %d, reported unstable %d, not applicable %d, silent NaN %d\n", totals["finite"],
              totals["reported"], totals["not-applicable"], totals["silent-nan"]);
  if (totals["silent-nan"] == 0) {
    std::printf("no silent NaN: every cell stayed finite or was reported\n");
    return 0;
  }
  int shown = 0;
  for (const Cell& cell : cells) {
    if (cell.outcome != "silent-nan" || shown++ >= 10) continue;
    std::printf("  silent NaN: %s k=%s dt=%g ratio=%g %s K=%d, %s\n", cell.method.c_str(),
                stiffness_text(cell.stiffness).c_str(), cell.dt, cell.mass_ratio, cell.geometry.c_str(),
                cell.iterations, cell.message.c_str());
  }
  std::fprintf(stderr, "extremes: %d silent NaN cell(s) (a bug: see %s)\n", totals["silent-nan"],
               cl::join_path(options.out, "extremes.csv").c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{"The extremes matrix: every solver at extreme stiffness, step, mass ratio and geometry "
                      "(bench/README.md). Exits 1 on any silent NaN.",
                      "extremes"};
  Options options;
  app.add_flag("--quick", options.quick, "CI size: 8 steps per cell, 2 with 10,000 iterations");
  app.add_option("--out", options.out, "folder for the CSV files").capture_default_str();
  app.add_option("--methods", options.methods,
                 "gs-pbd, jacobi-pbd, hpbd, xpbd, pd, newton, kkt, schur, schur-kg, limit-springs, limit-triangles, "
                 "pd-chebyshev, pd-lbfgs, jacobi-chebyshev, vbd, vbd-chebyshev, constrained-newton, "
                 "constrained-newton-drop")
      .delimiter(',');
  app.add_option("--steps", options.steps, "steps per cell (default 120, quick 8)").range(1, 1'000'000);
  app.add_option("--long-steps", options.long_steps, "steps of the 10,000-iteration cells (default 12, quick 2)")
      .range(1, 1'000'000);
  app.add_option("--threads", options.threads, "OpenMP threads for the Jacobi and VBD sweeps, BLAS threads for CHOLMOD")
      .range(1, 256)
      .capture_default_str();
  return cl::run_main(app, argc, argv, [&] { return run(options); });
}
