// Lab 05 — given code: the mass-spring step with a strain limiter, and the run loop.
#include "simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/metrics.h"

namespace cl::lab05 {

const char* limit_name(Limit limit) {
  switch (limit) {
    case Limit::kNone: return "none";
    case Limit::kSprings: return "springs";
    case Limit::kTrianglesArea: return "triangles-area";
    case Limit::kTrianglesStretch: return "triangles-stretch";
  }
  return "?";
}

Limit parse_limit(const std::string& name) {
  for (const Limit limit : {Limit::kNone, Limit::kSprings, Limit::kTrianglesArea, Limit::kTrianglesStretch}) {
    if (name == limit_name(limit)) return limit;
  }
  throw std::invalid_argument("unknown limit \"" + name + "\" (none, springs, triangles-area, triangles-stretch)");
}

bool limits_triangles(Limit limit) {
  return limit == Limit::kTrianglesArea || limit == Limit::kTrianglesStretch;
}

namespace {
Eigen::Matrix3d corners_of(const Eigen::Matrix3Xd& x, const Triangle& triangle) {
  Eigen::Matrix3d corners;
  corners << x.col(triangle.i), x.col(triangle.j), x.col(triangle.k);
  return corners;
}
}  // namespace

LimitedSystem make_limited_system(const Scene& scene, Limit limit) {
  for (std::size_t s = 0; s < scene.springs.size(); ++s) {
    const Spring& spring = scene.springs[s];
    const std::string field = scene.source + ": springs[" + std::to_string(s) + "]";
    if (!std::isfinite(spring.stiffness)) {
      throw InputError(field + ".stiffness: \"inf\" is a hard constraint with no Hooke force; lab 05 needs a "
                               "finite stiffness (N/m)");
    }
    if (!(spring.rest_length > 0.0)) {
      throw InputError(field + ".rest: 0, but the strain ℓ/L is undefined for a rest length of 0; lab 05 needs "
                               "rest > 0");
    }
  }
  LimitedSystem system;
  system.springs = scene.springs;
  if (!limits_triangles(limit)) return system;
  if (scene.triangles.empty()) {
    throw InputError(scene.source + ": triangles: the scene has none, so --limit " + limit_name(limit) +
                     " has nothing to limit (use --limit springs or none)");
  }
  system.triangles = scene.triangles;
  if (limit == Limit::kTrianglesStretch) {
    system.rests.reserve(scene.triangles.size());
    for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
      try {
        system.rests.push_back(make_triangle_rest(corners_of(scene.particles.x, scene.triangles[t])));
      } catch (const std::invalid_argument& error) {
        throw InputError(scene.source + ": triangles[" + std::to_string(t) + "]: " + error.what());
      }
    }
  }
  return system;
}

void limited_step(Particles& particles, const LimitedSystem& system, const StepSettings& settings) {
  const double dt = settings.dt;
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    throw std::invalid_argument("limited_step: dt must be finite and > 0 (got " + std::to_string(dt) + ")");
  }
  if (settings.iterations < 0) {
    throw std::invalid_argument("limited_step: iterations must be >= 0 (got " +
                                std::to_string(settings.iterations) + ")");
  }
  const Eigen::Index n = particles.size();
  if (particles.v.cols() != n || particles.inv_mass.size() != n) {
    throw std::invalid_argument("limited_step: x, v and inv_mass disagree in size");
  }
  const Eigen::VectorXd& w = particles.inv_mass;

  // 1. Hooke forces, then symplectic Euler for the prediction.
  Eigen::Matrix3Xd force = Eigen::Matrix3Xd::Zero(3, n);
  for (const Spring& spring : system.springs) {
    const Eigen::Vector3d d = particles.x.col(spring.i) - particles.x.col(spring.j);
    const double length = d.norm();
    if (length == 0.0) continue;
    const Eigen::Vector3d pull = (-spring.stiffness * (length - spring.rest_length) / length) * d;
    force.col(spring.i) += pull;
    force.col(spring.j) -= pull;
  }
  Eigen::Matrix3Xd predicted = particles.x;
  Eigen::Matrix3Xd velocity = particles.v;
  for (Eigen::Index p = 0; p < n; ++p) {
    if (w[p] > 0.0) {
      velocity.col(p) += dt * (settings.gravity + w[p] * force.col(p));
      predicted.col(p) += dt * velocity.col(p);
    } else {
      velocity.col(p).setZero();
    }
  }

  // 2. K Gauss-Seidel sweeps of the limiter, in file order.
  Eigen::Matrix3Xd limited = predicted;
  const double low = settings.sigma_min, high = settings.sigma_max;
  for (int k = 0; k < settings.iterations; ++k) {
    switch (settings.limit) {
      case Limit::kNone:
        break;
      case Limit::kSprings:
        for (const Spring& spring : system.springs) {
          const lab01::DistanceCorrection correction = limit_spring(
              limited.col(spring.i), limited.col(spring.j), w[spring.i], w[spring.j], spring.rest_length, low, high);
          limited.col(spring.i) += correction.dx_i;
          limited.col(spring.j) += correction.dx_j;
        }
        break;
      case Limit::kTrianglesArea:
      case Limit::kTrianglesStretch:
        for (std::size_t t = 0; t < system.triangles.size(); ++t) {
          const Triangle& triangle = system.triangles[t];
          const Eigen::Vector3d inv_mass(w[triangle.i], w[triangle.j], w[triangle.k]);
          const Eigen::Matrix3d corners = corners_of(limited, triangle);
          const Eigen::Matrix3d correction =
              settings.limit == Limit::kTrianglesArea
                  ? limit_triangle_area(corners, inv_mass, triangle.rest_area, low, high)
                  : limit_triangle_stretch(corners, inv_mass, system.rests[t], low, high);
          limited.col(triangle.i) += correction.col(0);
          limited.col(triangle.j) += correction.col(1);
          limited.col(triangle.k) += correction.col(2);
        }
        break;
    }
  }

  // 3. What the limiter moved becomes a velocity change. The particles are only
  // written here, so a limiter that throws leaves them as they were.
  particles.v = velocity + (limited - predicted) / dt;
  particles.x = limited;
}

double band_tolerance(int iterations) {
  return iterations > 0 ? 0.5 / iterations : std::numeric_limits<double>::infinity();
}

SignedStrain signed_strain(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  SignedStrain strain;
  for (std::size_t s = 0; s < springs.size(); ++s) {
    const Spring& spring = springs[s];
    const double value = (x.col(spring.i) - x.col(spring.j)).norm() / spring.rest_length - 1.0;
    if (std::isnan(value)) return {value, value};
    strain.max = s == 0 ? value : std::max(strain.max, value);
    strain.min = s == 0 ? value : std::min(strain.min, value);
  }
  return strain;
}

double elastic_energy(const Eigen::Matrix3Xd& x, const std::vector<Spring>& springs) {
  double energy = 0.0;
  for (const Spring& spring : springs) {
    const double stretch = (x.col(spring.i) - x.col(spring.j)).norm() - spring.rest_length;
    energy += 0.5 * spring.stiffness * stretch * stretch;
  }
  return energy;
}

double band_energy(const std::vector<Spring>& springs, double sigma_min, double sigma_max) {
  const double reach = std::max(sigma_max - 1.0, 1.0 - sigma_min);
  double energy = 0.0;
  for (const Spring& spring : springs) {
    const double stretch = reach * spring.rest_length;
    energy += 0.5 * spring.stiffness * stretch * stretch;
  }
  return energy;
}

bool energy_contained(const RunResult& result, bool band_held) {
  return result.problem.empty() && result.energy_exceeded_step >= 0 && band_held &&
         result.max_energy_rise <= result.energy_bound;
}

RunResult run_steps(Particles& particles, const LimitedSystem& system, const StepSettings& settings, int steps,
                    bool check_energy, const StepCallback& on_step, const FrameOutput& output) {
  if (steps < 0) throw std::invalid_argument("run_steps: steps must be >= 0 (got " + std::to_string(steps) + ")");
  RunResult result;
  result.energy_scale = energy_scale(particles, settings.gravity, settings.dt);
  result.energy_bound = result.energy_scale;
  if (settings.limit != Limit::kNone && settings.iterations > 0) {
    result.energy_bound += band_energy(system.springs, settings.sigma_min, settings.sigma_max);
  }
  FramePlan loop = frame_plan(steps, settings.dt, result.energy_scale);
  loop.energy_verdict = check_energy ? EnergyVerdict::kStop : EnergyVerdict::kReport;

  StepRecord record;
  auto step = [&](int) {
    limited_step(particles, system, settings);
    return StepVerdict{};
  };
  auto measure = [&](int s, double seconds) {
    record = StepRecord{};
    record.step = s;
    record.time = s * settings.dt;
    record.strain = signed_strain(particles.x, system.springs);
    const StrainStats error = strain_stats(particles.x, system.springs);
    record.rms_strain_error = error.rms;
    record.kinetic = kinetic_energy(particles);
    record.potential = potential_energy(particles, settings.gravity);
    record.elastic = elastic_energy(particles.x, system.springs);
    record.seconds = seconds;
    const double total = record.kinetic + record.potential + record.elastic;
    FrameMeasure measured{error, total, {},
                          {record.strain.max, record.strain.min, record.rms_strain_error, record.kinetic,
                           record.potential, record.elastic, total, seconds},
                          {}};
    if (s == 0) return measured;
    if (s == 1 || !(record.strain.max <= result.max_strain)) {
      result.max_strain = record.strain.max;
      result.max_strain_step = s;
    }
    if (s == 1 || !(record.strain.min >= result.min_strain)) {
      result.min_strain = record.strain.min;
      result.min_strain_step = s;
    }
    if (!std::isfinite(record.elastic + record.kinetic)) measured.problem = "energy is not finite";
    return measured;
  };
  FrameOutput with_index = output;
  with_index.index_column = "step";
  with_index.problem_prefix = "unstable: ";
  const FrameLoopResult run = run_frame_loop(particles, step, measure, loop, with_index, record_hook(record, on_step));

  copy_outcome(run, result, result.steps_done, result.problem_step);
  result.energy_start = run.energy_start;
  result.energy_end = run.energy_end;
  result.max_energy_rise = run.max_energy_rise;
  result.energy_exceeded_step = run.energy_exceeded_frame;
  result.energy_exceeded = run.energy_exceeded;
  return result;
}

std::vector<std::string> step_columns() {
  return {"max_strain", "min_strain", "rms_strain_error", "kinetic", "potential", "elastic", "total_energy", "seconds"};
}

}  // namespace cl::lab05
