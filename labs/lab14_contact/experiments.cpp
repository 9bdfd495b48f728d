// Lab 14 — given code: the experiments.
#include "experiments.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "common/csv.h"
#include "common/driver.h"
#include "common/metrics.h"
#include "common/output.h"

namespace cl::lab14 {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kRestKineticPerKg = 1e-4;  // J/kg: an rms speed of 1.4 cm/s
const char* const kMethods[] = {"pbd", "xpbd", "constrained"};

// The options an experiment's start_run sees: it runs every method, so
// --check names none ("--method pbd", the default, would say it runs one).
CommonOptions every_method(const CommonOptions& options) {
  CommonOptions shown = options;
  shown.method.clear();
  return shown;
}
}  // namespace

StepSettings step_settings(const Scene& scene, const CommonOptions& options, const LabOptions& lab) {
  StepSettings settings;
  settings.method = method_from_name(options.method);
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.iterations = options.iterations;
  settings.friction = lab.friction;
  return settings;
}

namespace {
// A list flag's numbers, "0,0.3,1" (the flag may be repeated): every entry is
// one, named by its index when it is not.
std::vector<double> read_numbers(const std::string& flag, const std::vector<std::string>& given) {
  std::vector<double> values;
  for (const std::string& text : given) {
    std::size_t begin = 0;
    for (;;) {
      const std::size_t comma = text.find(',', begin);
      const std::string entry = text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
      const std::string where = flag + "[" + std::to_string(values.size()) + "]";
      if (entry.empty()) throw InputError(where + ": empty (a number goes between the commas)");
      char* end = nullptr;
      const double value = std::strtod(entry.c_str(), &end);
      if (end != entry.c_str() + entry.size() || !std::isfinite(value)) {
        throw InputError(where + ": '" + entry + "' is not a finite number");
      }
      values.push_back(value);
      if (comma == std::string::npos) break;
      begin = comma + 1;
    }
  }
  return values;
}
}  // namespace

void check_lab_options(LabOptions& lab) {
  lab.frictions = read_numbers("--frictions", lab.frictions_given);
  lab.angles = read_numbers("--angles", lab.angles_given);
  if (!lab.drape && !lab.incline) {
    if (!lab.frictions_given.empty()) throw InputError("--frictions: only with --drape or --incline");
    if (!lab.angles_given.empty()) throw InputError("--angles: only with --incline");
  }
  if (lab.drape && !lab.angles_given.empty()) throw InputError("--angles: only with --incline");
  for (std::size_t f = 0; f < lab.frictions.size(); ++f) {
    if (!(std::isfinite(lab.frictions[f]) && lab.frictions[f] >= 0.0 && lab.frictions[f] <= kMaxFriction)) {
      throw InputError("--frictions[" + std::to_string(f) + "]: must be a finite number >= 0 and <= 1e6 (got " +
                       std::to_string(lab.frictions[f]) + ")");
    }
  }
}

Eigen::Vector3d centre_of_mass(const Particles& particles) {
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  double mass = 0.0;
  for (Eigen::Index i = 0; i < particles.size(); ++i) {
    if (particles.inv_mass[i] <= 0.0) continue;
    weighted += particles.x.col(i) / particles.inv_mass[i];
    mass += 1.0 / particles.inv_mass[i];
  }
  return mass > 0.0 ? Eigen::Vector3d(weighted / mass) : Eigen::Vector3d::Zero();
}

double sideways_drift(const Eigen::Vector3d& start, const Eigen::Vector3d& end, const Eigen::Vector3d& gravity) {
  const Eigen::Vector3d move = end - start;
  const double g = gravity.norm();
  if (!(g > 0.0)) return move.norm();
  const Eigen::Vector3d down = gravity / g;
  return Eigen::Vector3d(move - move.dot(down) * down).norm();
}

void report_initial_penetration(const char* lab_name, const InitialPenetration& initial) {
  std::fprintf(stderr,
               "%s: %d particle(s) start inside a collider, the deepest %.6g m (particle %d); moved out to the "
               "surface before frame 0, velocities unchanged%s\n",
               lab_name, initial.particles, initial.deepest, initial.worst_particle,
               initial.left > 1e-12 ? " (overlapping colliders left one inside)" : "");
}

Scene incline_scene(double degrees, double friction, int steps) {
  const double theta = degrees * kPi / 180.0;
  Scene scene;
  scene.name = "incline";
  scene.dt = 1.0 / 60.0;
  scene.steps = steps;
  scene.particles.x = Eigen::Matrix3Xd::Zero(3, 1);
  scene.particles.v = Eigen::Matrix3Xd::Zero(3, 1);
  scene.particles.inv_mass = Eigen::VectorXd::Ones(1);
  Collider plane;
  plane.shape = ColliderShape::kPlane;
  plane.normal = Eigen::Vector3d(-std::sin(theta), std::cos(theta), 0.0);
  plane.friction = friction;
  scene.colliders.push_back(plane);
  return scene;
}

int run_drape(const char* lab_name, const std::string& scene_dir, const CommonOptions& options, const LabOptions& lab) {
  refuse_run_flags(options, "--drape writes drape.csv, not one run's trajectory",
                   "--drape writes drape.csv, not one run's summary");
  if (lab.friction) throw InputError("--friction: --drape sweeps --frictions instead");
  Scene loaded = load_scene_for(options, scene_dir);
  start_run(every_method(options));  // --check stops here, before the initial penetration pass runs your code
  const InitialPenetration initial = resolve_initial_penetration(loaded.particles, loaded.colliders);
  if (initial.particles > 0) report_initial_penetration(lab_name, initial);
  double mass = 0.0;
  for (Eigen::Index i = 0; i < loaded.particles.size(); ++i) {
    if (loaded.particles.inv_mass[i] > 0.0) mass += 1.0 / loaded.particles.inv_mass[i];
  }
  CsvTable table({"method", "friction", "iterations", "steps_done", "max_penetration", "energy_start", "energy_end",
                  "seconds_per_step", "rest_time", "max_normal_force", "moved_back", "centre_of_mass_drift",
                  "status"});
  std::printf("%s --drape: scene %s, K = %d, %d steps of %.4g s\n", lab_name, describe(loaded).c_str(),
              options.iterations, loaded.steps, loaded.dt);
  std::printf("  %-12s %5s %14s %14s %14s %12s\n", "method", "mu", "penetration m", "energy end J", "s per step",
              "rest at s");
  for (const char* method : kMethods) {
    for (const double mu : lab.frictions.empty() ? kFrictions : lab.frictions) {
      Scene scene = loaded;
      CommonOptions one = options;
      one.method = method;
      LabOptions with = lab;
      with.friction = mu;
      ContactStepper stepper(scene, step_settings(scene, one, with));
      int rest_from = -1;
      const FrameCallback on_frame = [&](const FrameRecord& record, const Particles&) {
        if (record.kinetic / mass < kRestKineticPerKg) {
          if (rest_from < 0) rest_from = record.frame;
        } else {
          rest_from = -1;
        }
      };
      const Eigen::Vector3d centre_start = centre_of_mass(scene.particles);
      const RunResult run = run_steps(scene.particles, stepper, scene.springs, scene.colliders, scene.steps, on_frame);
      const double per_step = run.steps_done > 0 ? run.seconds / run.steps_done : 0.0;
      const bool rested = rest_from >= 0 && run.problem.empty();
      table.add_row({std::string(method), mu, static_cast<long long>(options.iterations),
                     static_cast<long long>(run.steps_done), run.max_penetration, run.energy_start, run.energy_end,
                     per_step, cell_if(rested, rest_from * scene.dt), run.max_normal_force, run.moved_back,
                     sideways_drift(centre_start, centre_of_mass(scene.particles), scene.gravity),
                     run.problem.empty() ? std::string("ok") : run.problem});
      std::printf("  %-12s %5.2f %14.3e %14.6g %14.3e %12s\n", method, mu, run.max_penetration, run.energy_end,
                  per_step, rested ? std::to_string(rest_from * scene.dt).substr(0, 6).c_str() : "-");
    }
  }
  if (!options.out.empty()) table.write(join_path(options.out, "drape.csv"));
  return 0;
}

int run_incline(const char* lab_name, const CommonOptions& options, const LabOptions& lab) {
  refuse_run_flags(options, "--incline writes incline.csv, not one run's trajectory",
                   "--incline writes incline.csv, not one run's summary");
  if (lab.friction) throw InputError("--friction: --incline sweeps --frictions instead");
  if (options.scene != kDefaultScene) throw InputError("--scene: --incline builds its own scenes (incline_scene)");
  if (options.steps >= 0) throw InputError("--steps: --incline takes 100 steps of 1/60 s");
  if (options.dt > 0.0) throw InputError("--dt: --incline takes 100 steps of 1/60 s");
  const std::vector<double>& angles = lab.angles.empty() ? kAngles : lab.angles;
  for (std::size_t a = 0; a < angles.size(); ++a) {
    if (!(angles[a] > 0.0 && angles[a] < 90.0)) {
      throw InputError("--angles[" + std::to_string(a) + "]: must be in (0, 90) degrees (got " +
                       std::to_string(angles[a]) + ")");
    }
  }
  start_run(every_method(options));
  constexpr int kSteps = 100;
  CsvTable table({"method", "friction", "angle_deg", "tan_angle", "sticks", "acceleration", "coulomb_acceleration"});
  std::printf("%s --incline: a 1 kg particle on a plane tilted by θ, %d steps of 1/60 s, K = %d\n", lab_name, kSteps,
              options.iterations);
  std::printf("  %-12s %5s %18s %18s %10s\n", "method", "mu", "largest θ sticking", "smallest θ sliding", "atan μ");
  for (const char* method : kMethods) {
    for (const double mu : lab.frictions.empty() ? kFrictions : lab.frictions) {
      double stick_max = -1.0, slide_min = 1e9;
      for (const double degrees : angles) {
        Scene scene = incline_scene(degrees, mu, kSteps);
        CommonOptions one = options;
        one.method = method;
        ContactStepper stepper(scene, step_settings(scene, one, LabOptions{}));
        run_steps(scene.particles, stepper, scene.springs, scene.colliders, kSteps);
        const double theta = degrees * kPi / 180.0;
        const Eigen::Vector3d down_slope(-std::cos(theta), -std::sin(theta), 0.0);
        const bool sticks = scene.particles.x.col(0).norm() < 1e-12;
        const double acceleration = scene.particles.v.col(0).dot(down_slope) / (kSteps * scene.dt);
        const double coulomb = std::max(0.0, 9.81 * (std::sin(theta) - mu * std::cos(theta)));
        table.add_row({std::string(method), mu, degrees, std::tan(theta), static_cast<long long>(sticks), acceleration,
                       coulomb});
        if (sticks) stick_max = std::max(stick_max, degrees);
        else slide_min = std::min(slide_min, degrees);
      }
      std::printf("  %-12s %5.2f %18s %18s %10.4g\n", method, mu,
                  stick_max >= 0 ? std::to_string(stick_max).substr(0, 6).c_str() : "-",
                  slide_min < 1e9 ? std::to_string(slide_min).substr(0, 6).c_str() : "-",
                  std::atan(mu) * 180.0 / kPi);
    }
  }
  if (!options.out.empty()) table.write(join_path(options.out, "incline.csv"));
  return 0;
}

}  // namespace cl::lab14
