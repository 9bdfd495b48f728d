// The extremes matrix (issue 12, docs/DESIGN.md §6): every solver of labs
// 04-13 × stiffness × Δt × mass ratio × geometry × iteration count on a small
// curtain; and lab 14's three steps with contact (issue 34) on the same
// curtain with colliders × approach speed × friction × the same extremes.
// Each cell ends one of five ways:
//   finite          every step done, the state finite and bounded (and, with
//                   colliders, no particle inside one at the end);
//   reported        the program said it went wrong: the step reported a
//                   problem or threw with a message, or the health check of
//                   common/health.h stopped the run (strain >= 1e3, energy
//                   rising more than energy_scale above its start);
//   not-applicable  the method rejects the scene with a clear error (PD and a
//                   hard spring, lab 05 and a zero rest length);
//   silent-nan      a step reported nothing yet left a non-finite state: a bug;
//   inside          every step done and reported nothing, yet at the end a
//                   movable particle lies deeper than 1e-6 m inside a
//                   collider: a bug too.
// Exits 1 when any cell is silent-nan or inside. Details: bench/README.md.
//
//   extremes [--quick] [--out DIR] [--methods a,b] [--steps N] [--long-steps N]
//
// Writes DIR/extremes.csv (one row per cell) and DIR/extremes_counts.csv.
#include <algorithm>
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
#endif

#include <Eigen/Core>

#include "common/cli.h"
#include "common/csv.h"
#include "common/health.h"
#include "common/metrics.h"
#include "common/openmp.h"
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
const std::vector<std::string> kOutcomes{"finite", "reported", "not-applicable", "silent-nan", "inside"};

// The contact cells: lab 14's methods on the curtain with colliders below its
// hem (collider_set), at rest or thrown at them so fast that one step would
// cross every collider (approach speed 2 m per step, whatever Δt), without
// friction and with μ = 10, over the stiffness, Δt and iteration axes above,
// mass ratios 1 and 1e6, and the geometries that apply to springs alone.
const std::vector<std::string> kColliderSets{"plane", "sphere", "thin-capsule", "all"};
const std::vector<std::string> kSpeeds{"rest", "fast"};
const std::vector<double> kFrictions{0.0, 10.0};
const std::vector<double> kContactMassRatio{1.0, 1e6};
const std::vector<std::string> kContactGeometry{"normal", "coincident", "zero-rest"};
constexpr double kInsideDepth = 1e-6;  // m: deeper than this at a cell's end is "inside"

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

// The colliders under the curtain (its hem is the row at y = 0, x from −0.5
// to 0.5, z = 0), each with friction μ:
//   plane         through (0, −0.1, 0), normal (0.2, 1, 0)/‖·‖: tilted, so
//                 that gravity has a part along it; the hem's left corner
//                 starts on it;
//   sphere        centre (0, −0.15, 0), radius 0.2: its top 5 cm above the
//                 hem's height, between the hem's particles;
//   thin-capsule  from (−1, −0.05, 0) to (1, −0.05, 0), radius 1e-4 m,
//                 right across the path of every falling particle;
//   all           the three together: the sphere sunk into the plane, the
//                 capsule through both (a particle can touch two at once).
std::vector<cl::Collider> collider_set(const std::string& set, double friction) {
  cl::Collider plane;
  plane.shape = cl::ColliderShape::kPlane;
  plane.a = Eigen::Vector3d(0.0, -0.1, 0.0);
  plane.normal = Eigen::Vector3d(0.2, 1.0, 0.0).normalized();
  cl::Collider sphere;
  sphere.shape = cl::ColliderShape::kSphere;
  sphere.a = Eigen::Vector3d(0.0, -0.15, 0.0);
  sphere.radius = 0.2;
  cl::Collider capsule;
  capsule.shape = cl::ColliderShape::kCapsule;
  capsule.a = Eigen::Vector3d(-1.0, -0.05, 0.0);
  capsule.b = Eigen::Vector3d(1.0, -0.05, 0.0);
  capsule.radius = 1e-4;
  std::vector<cl::Collider> colliders;
  if (set == "plane" || set == "all") colliders.push_back(plane);
  if (set == "sphere" || set == "all") colliders.push_back(sphere);
  if (set == "thin-capsule" || set == "all") colliders.push_back(capsule);
  for (cl::Collider& collider : colliders) collider.friction = friction;
  return colliders;
}

// The signed distance to a collider's surface (> 0 outside), written here
// from the definitions (docs/DESIGN.md §3) rather than taken from lab 14, so
// that the check does not share the code it checks.
double signed_distance(const cl::Collider& collider, const Eigen::Vector3d& x) {
  switch (collider.shape) {
    case cl::ColliderShape::kPlane: return collider.normal.dot(x - collider.a);
    case cl::ColliderShape::kSphere: return (x - collider.a).norm() - collider.radius;
    case cl::ColliderShape::kCapsule: {
      const Eigen::Vector3d axis = collider.b - collider.a;
      const double length2 = axis.squaredNorm();
      const double t = length2 > 0.0 ? std::clamp((x - collider.a).dot(axis) / length2, 0.0, 1.0) : 0.0;
      return (x - (collider.a + t * axis)).norm() - collider.radius;
    }
  }
  return 0.0;
}

struct Depth {
  double depth = 0.0;  // m, >= 0
  int particle = -1, collider = -1;
};

// The deepest a movable particle lies inside a collider (pinned particles are
// the scene's business, not the contact step's).
Depth deepest(const cl::Particles& particles, const std::vector<cl::Collider>& colliders) {
  Depth found;
  for (Eigen::Index i = 0; i < particles.x.cols(); ++i) {
    if (!(particles.inv_mass[i] > 0.0)) continue;
    for (std::size_t c = 0; c < colliders.size(); ++c) {
      const double depth = -signed_distance(colliders[c], particles.x.col(i));
      if (depth > found.depth) found = {depth, static_cast<int>(i), static_cast<int>(c)};
    }
  }
  return found;
}

// One cell's extremes. `colliders` "none": a spring cell of labs 04-13.
struct CellSpec {
  double stiffness = 0, dt = 0, mass_ratio = 0;
  std::string geometry;
  int iterations = 0, steps = 0;
  std::string colliders = "none", speed = "rest";
  double friction = 0;
};

// The scene of one cell: the solver sees these springs, masses, Δt and
// colliders; the geometry's change of the positions comes after the solver is
// built (so that a rest shape, lab 05's triangles or lab 10's hierarchy, stays
// the curtain's). "fast": every movable particle starts at (0.25, −2, 0)/Δt,
// down and sideways, 2 m a step: through every collider in one step.
cl::Scene cell_scene(const cl::Scene& base, const CellSpec& spec) {
  cl::Scene scene = base;
  scene.dt = spec.dt;
  for (cl::Spring& spring : scene.springs) {
    spring.stiffness = spec.stiffness;
    if (spec.geometry == "zero-rest") spring.rest_length = 0.0;
  }
  for (int col = 0; col < kN; ++col) scene.particles.inv_mass[id(kN - 1, col)] /= spec.mass_ratio;  // a heavy hem
  if (spec.colliders != "none") scene.colliders = collider_set(spec.colliders, spec.friction);
  if (spec.speed == "fast") {
    for (Eigen::Index i = 0; i < scene.particles.x.cols(); ++i) {
      if (scene.particles.inv_mass[i] > 0.0) scene.particles.v.col(i) = Eigen::Vector3d(0.25, -2.0, 0.0) / spec.dt;
    }
  }
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
  std::string method;
  CellSpec spec;
  std::string outcome, message;
  double max_strain = 0, seconds = 0;
  double depth = 0;  // the deepest a movable particle was inside a collider at any step's end, m
  int steps_done = 0;
};

double energy(const cl::Particles& particles, const cl::Scene& scene, bool elastic) {
  double e = cl::kinetic_energy(particles) + cl::potential_energy(particles, scene.gravity);
  if (elastic) e += cl::bench::elastic_energy(particles.x, scene.springs);
  return e;
}

Cell run_cell(const cl::Scene& base, const cl::bench::MethodInfo& method, const CellSpec& spec) {
  Cell cell;
  cell.method = method.name;
  cell.spec = spec;
  const double dt = spec.dt;
  const cl::Timer timer;
  const cl::Scene scene = cell_scene(base, spec);
  std::unique_ptr<cl::bench::Stepper> stepper;
  try {
    stepper = cl::bench::make_stepper(method.name, scene, spec.iterations);
  } catch (const std::exception& error) {  // std::invalid_argument or cl::InputError, with the lab's message
    cell.outcome = "not-applicable";
    cell.message = error.what();
    return cell;
  }
  cl::Particles state = scene.particles;
  deform(state, spec.geometry);

  // The energy check of the method's own lab: lab 04 and lab 08 count kinetic
  // and gravity only, lab 06, 07 and 09 the springs too; lab 05 checks no
  // energy when limiting (its springs may store far more, bounded by the band);
  // lab 14 counts kinetic and gravity for all three of its methods.
  const bool contact = cl::bench::models_colliders(method);
  const bool check_energy = method.family != Family::kLimited;
  const bool elastic = !contact && (method.family == Family::kImplicitEuler ? method.name != "xpbd"
                                                                            : method.family == Family::kLinearized);
  const double e0 = energy(state, scene, elastic);
  const double allowance = cl::energy_scale(state, scene.gravity, dt) +
                           (elastic ? 0.0 : cl::bench::elastic_energy(state.x, scene.springs));
  for (int step = 1; step <= spec.steps; ++step) {
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
    if (!scene.colliders.empty()) cell.depth = std::max(cell.depth, deepest(state, scene.colliders).depth);
  }
  if (cell.outcome.empty() && !scene.colliders.empty()) {
    const Depth end = deepest(state, scene.colliders);
    if (end.depth > kInsideDepth) {
      char text[160];
      std::snprintf(text, sizeof text, "after step %d: particle %d is %.3g m inside collider %d (%s), unreported",
                    cell.steps_done, end.particle, end.depth, end.collider,
                    cl::shape_name(scene.colliders[static_cast<std::size_t>(end.collider)].shape));
      cell.outcome = "inside";
      cell.message = text;
    }
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

// The --quick subset of the contact cells (bench/README.md), about a tenth
// of their time: every cell with K = 1 (about 1 ms each), and with K = 10,000
// (about 60 ms each) only the overlapping colliders ("all"), the normal
// geometry, the heavy hem (1e6) and Δt = 0.5 s (the step that crosses
// everything), every stiffness, speed and friction.
bool in_quick_contact(const CellSpec& spec) {
  if (spec.iterations == 1) return true;
  return spec.colliders == "all" && spec.geometry == "normal" && spec.mass_ratio == 1e6 && spec.dt == 0.5;
}

// The cells of one method: the curtain matrix for a spring method, the
// contact matrix for one of lab 14's (quick: its subset, bench/README.md).
std::vector<CellSpec> cells_of(const cl::bench::MethodInfo& method, const Options& options, int steps, int long_steps) {
  std::vector<CellSpec> specs;
  const bool contact = cl::bench::models_colliders(method);
  for (const int iterations : kIterations) {
    for (const std::string& geometry : contact ? kContactGeometry : kGeometry) {
      for (const double stiffness : kStiffness) {
        for (const double dt : kDt) {
          for (const double ratio : contact ? kContactMassRatio : kMassRatio) {
            CellSpec spec;
            spec.stiffness = stiffness;
            spec.dt = dt;
            spec.mass_ratio = ratio;
            spec.geometry = geometry;
            spec.iterations = iterations;
            spec.steps = iterations > 1 ? long_steps : steps;
            if (!contact) {
              specs.push_back(spec);
              continue;
            }
            for (const std::string& colliders : kColliderSets) {
              for (const std::string& speed : kSpeeds) {
                for (const double friction : kFrictions) {
                  spec.colliders = colliders;
                  spec.speed = speed;
                  spec.friction = friction;
                  if (!options.quick || in_quick_contact(spec)) specs.push_back(spec);
                }
              }
            }
          }
        }
      }
    }
  }
  return specs;
}

std::string counts_text(std::map<std::string, int>& c) {
  char text[160];
  std::snprintf(text, sizeof text, "finite %4d  reported %4d  not applicable %3d  silent NaN %d  inside %d",
                c["finite"], c["reported"], c["not-applicable"], c["silent-nan"], c["inside"]);
  return text;
}

int run(const Options& options) {
  std::vector<const cl::bench::MethodInfo*> methods;
  if (options.methods.empty()) {
    for (const cl::bench::MethodInfo& method : cl::bench::all_methods()) methods.push_back(&method);
    for (const cl::bench::MethodInfo& method : cl::bench::contact_methods()) methods.push_back(&method);
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
  cl::start_run(options.out);
#ifdef _OPENMP
  cl::set_openmp_threads(options.threads);
  cl::set_blas_threads(options.threads);  // CHOLMOD's BLAS too: serial methods, timed side by side
#endif
  const cl::Scene base = base_scene();
  std::vector<std::vector<CellSpec>> plan;
  std::size_t spring_methods = 0, contact_methods = 0, spring_cells = 0, contact_cells = 0;
  for (const cl::bench::MethodInfo* method : methods) {
    plan.push_back(cells_of(*method, options, steps, long_steps));
    const bool contact = cl::bench::models_colliders(*method);
    ++(contact ? contact_methods : spring_methods);
    (contact ? contact_cells : spring_cells) += plan.back().size();
  }
  std::printf("extremes:");
  if (spring_methods > 0) {
    std::printf(" %zu methods x %zu cells on a %dx%d curtain", spring_methods, spring_cells / spring_methods, kN, kN);
  }
  if (contact_methods > 0) {
    std::printf("%s %zu contact methods x %zu cells with colliders", spring_methods > 0 ? "," : "",
                contact_methods, contact_cells / contact_methods);
  }
  std::printf("; %d steps (%d with 10,000 iterations)\n", steps, long_steps);
  std::fflush(stdout);

  const bool tty = isatty(fileno(stderr)) != 0;
  const cl::Timer total;
  std::vector<Cell> cells;
  std::map<std::string, std::map<std::string, int>> counts;
  for (std::size_t m = 0; m < methods.size(); ++m) {
    const cl::bench::MethodInfo* method = methods[m];
    const cl::Timer method_timer;
    for (const CellSpec& spec : plan[m]) {
      if (tty) {
        std::fprintf(stderr, "\r\033[K[%zu cells, %.0f s] %s K=%d %s k=%s dt=%g ratio=%g %s %s mu=%g", cells.size(),
                     total.seconds(), method->name.c_str(), spec.iterations, spec.geometry.c_str(),
                     stiffness_text(spec.stiffness).c_str(), spec.dt, spec.mass_ratio, spec.colliders.c_str(),
                     spec.speed.c_str(), spec.friction);
        std::fflush(stderr);
      }
      cells.push_back(run_cell(base, *method, spec));
      ++counts[method->name][cells.back().outcome];
    }
    if (tty) std::fprintf(stderr, "\r\033[K");
    std::printf("%-23s %s  (%.1f s)\n", method->name.c_str(), counts_text(counts[method->name]).c_str(),
                method_timer.seconds());
    std::fflush(stdout);
  }

  cl::CsvTable table({"method", "family", "stiffness", "dt", "mass_ratio", "geometry", "iterations", "steps",
                      "steps_done", "colliders", "speed", "friction", "outcome", "max_strain", "depth", "seconds",
                      "message"});
  for (const Cell& cell : cells) {
    const CellSpec& spec = cell.spec;
    table.add_row({cell.method, std::string(cl::bench::family_name(cl::bench::method_info(cell.method).family)),
                   stiffness_text(spec.stiffness), spec.dt, spec.mass_ratio, spec.geometry,
                   static_cast<long long>(spec.iterations), static_cast<long long>(spec.steps),
                   static_cast<long long>(cell.steps_done), spec.colliders, spec.speed, spec.friction, cell.outcome,
                   cell.max_strain, cell.depth, cell.seconds, one_line(cell.message)});
  }
  table.write(cl::join_path(options.out, "extremes.csv"));
  cl::CsvTable count_table({"method", "finite", "reported", "not_applicable", "silent_nan", "inside"});
  std::map<std::string, int> totals;
  auto count_row = [&](const std::string& name, std::map<std::string, int>& c) {
    count_table.add_row({name, static_cast<long long>(c["finite"]), static_cast<long long>(c["reported"]),
                         static_cast<long long>(c["not-applicable"]), static_cast<long long>(c["silent-nan"]),
                         static_cast<long long>(c["inside"])});
  };
  for (const cl::bench::MethodInfo* method : methods) {
    std::map<std::string, int>& c = counts[method->name];
    count_row(method->name, c);
    for (const std::string& outcome : kOutcomes) totals[outcome] += c[outcome];
  }
  count_row("total", totals);
  count_table.write(cl::join_path(options.out, "extremes_counts.csv"));

  std::printf("\nextremes: %zu cells in %.0f s; CSV in %s\n", cells.size(), total.seconds(), options.out.c_str());
  std::printf("finite %d, reported unstable %d, not applicable %d, silent NaN %d, inside %d\n", totals["finite"],
              totals["reported"], totals["not-applicable"], totals["silent-nan"], totals["inside"]);
  if (totals["silent-nan"] == 0 && totals["inside"] == 0) {
    std::printf("no silent NaN, no particle left inside: every cell stayed finite (and outside) or was reported\n");
    return 0;
  }
  int shown = 0;
  for (const Cell& cell : cells) {
    if ((cell.outcome != "silent-nan" && cell.outcome != "inside") || shown++ >= 10) continue;
    const CellSpec& spec = cell.spec;
    std::printf("  %s: %s k=%s dt=%g ratio=%g %s K=%d", cell.outcome.c_str(), cell.method.c_str(),
                stiffness_text(spec.stiffness).c_str(), spec.dt, spec.mass_ratio, spec.geometry.c_str(),
                spec.iterations);
    if (spec.colliders != "none") std::printf(" %s %s mu=%g", spec.colliders.c_str(), spec.speed.c_str(), spec.friction);
    std::printf(", %s\n", cell.message.c_str());
  }
  std::fprintf(stderr, "extremes: %d silent NaN and %d inside cell(s) (bugs: see %s)\n", totals["silent-nan"],
               totals["inside"], cl::join_path(options.out, "extremes.csv").c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  cl::CommandLine app{"The extremes matrix: every solver at extreme stiffness, step, mass ratio and geometry, lab 14's "
                      "with colliders too (bench/README.md). Exits 1 on any silent NaN or particle left inside.",
                      "extremes"};
  Options options;
  app.add_flag("--quick", options.quick, "CI size: 8 steps per cell, 2 with 10,000 iterations, and a subset of "
                                         "the contact cells");
  app.add_option("--out", options.out, "folder for the CSV files").capture_default_str();
  app.add_option("--methods", options.methods,
                 std::string("gs-pbd, jacobi-pbd, hpbd, xpbd, pd, newton, kkt, schur, schur-kg, limit-springs, "
                             "limit-triangles, pd-chebyshev, pd-lbfgs, jacobi-chebyshev, vbd, vbd-chebyshev, "
                             "constrained-newton, constrained-newton-drop") +
                     (cl::bench::contact_methods().empty()
                          ? "; not in this tree: lab 14's contact-pbd, contact-xpbd, contact-constrained (its "
                            "reference ships after its deadline)"
                          : "; with colliders: contact-pbd, contact-xpbd, contact-constrained"))
      .delimiter(',');
  app.add_option("--steps", options.steps, "steps per cell (default 120, quick 8)").range(1, 1'000'000);
  app.add_option("--long-steps", options.long_steps, "steps of the 10,000-iteration cells (default 12, quick 2)")
      .range(1, 1'000'000);
  app.add_option("--threads", options.threads, "OpenMP threads for the Jacobi and VBD sweeps, BLAS threads for CHOLMOD")
      .range(1, 256)
      .capture_default_str();
  return cl::run_main(app, argc, argv, [&] { return run(options); });
}
