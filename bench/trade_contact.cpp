// The speed/accuracy trade with contact (trade_contact.h; bench/README.md,
// "Contact in the trade").
#include "trade_contact.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/csv.h"
#include "common/output.h"
#include "common/scene.h"
#include "common/timer.h"
#include "methods.h"

#ifdef CL_BENCH_CONTACT
#include "labs/lab14_contact/contact_step.h"
#endif

namespace cl::bench {

namespace {

// The N of drape-N, or 0 when the name is not one.
int drape_size(const std::string& name) {
  if (name.rfind("drape-", 0) != 0) return 0;
  const std::string n = name.substr(6);
  if (n.empty() || n.size() > 3 || n.find_first_not_of("0123456789") != std::string::npos) return 0;
  const int size = std::stoi(n);
  return size >= 3 ? size : 0;
}

}  // namespace

bool is_contact_scene(const std::string& name) { return drape_size(name) > 0; }

#ifdef CL_BENCH_CONTACT
namespace {

// Lab 14's drape-sphere (labs/lab14_contact/scenes/drape-sphere.json) with an
// N x N cloth: 1 m square, 1 kg, flat in the xz plane at y = 0, structural,
// shear and bending springs of 1e4 N/m, over a sphere (radius 0.25 m, top
// 5 cm below the cloth) above a floor at y = -0.6 m, μ = 0.3 on both.
Scene drape_scene(const std::string& name) {
  const int n = drape_size(name);
  if (n == 0) throw InputError("--scenes: unknown scene '" + name + "' (rope-100, curtain-N or drape-N, N >= 3)");
  const std::string size = std::to_string(n);
  return parse_scene(R"({"name": ")" + name + R"(", "dt": 0.016666666666666666,
      "cloth": {"nx": )" + size + R"(, "ny": )" + size + R"(, "width": 1.0, "height": 1.0, "mass": 1.0,
                "plane": "xz", "springs": ["structural", "shear", "bending"], "stiffness": 1e4},
      "colliders": [
        {"type": "sphere", "centre": [0.0, -0.3, 0.5], "radius": 0.25, "friction": 0.3},
        {"type": "plane", "point": [0.0, -0.6, 0.0], "normal": [0.0, 1.0, 0.0], "friction": 0.3}]})",
                     "trade scene " + name);
}

lab14::Method lab_method(const std::string& name) {
  if (name == "contact-pbd") return lab14::Method::kPbd;
  if (name == "contact-xpbd") return lab14::Method::kXpbd;
  return lab14::Method::kConstrained;
}

// As methods.cpp's contact steppers: the scene's dt and gravity, each
// collider's own μ, K iterations.
lab14::ContactStepper make_contact_stepper(const Scene& scene, const std::string& method, int iterations) {
  lab14::StepSettings settings;
  settings.method = lab_method(method);
  settings.dt = scene.dt;
  settings.gravity = scene.gravity;
  settings.iterations = iterations;
  return lab14::ContactStepper(scene, settings);
}

// The CSV cell text (common/csv.h does not quote): no commas.
std::string csv_text(std::string text) {
  std::replace(text.begin(), text.end(), ',', ';');
  return text;
}

double rms_distance(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return a.cols() == 0 ? 0.0 : std::sqrt((a - b).colwise().squaredNorm().mean());
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// The reference: the constrained step with K doubled from 64 until two
// successive results differ by at most 1e-13 m RMS, K reaches 65,536, or the
// next K would take more than a minute. Its own accuracy is the last change.
struct ContactReference {
  Particles after;
  int iterations = 0;
  double change = 0.0;        // RMS distance to the result at K/2, m
  double displacement = 0.0;  // RMS of the step's move, m
  double seconds = 0.0;
  int contacts_found = 0, contacts_active = 0;
};

ContactReference reference_step(const Scene& scene, const Particles& start) {
  const Timer timer;
  ContactReference ref;
  Particles previous;
  double last_seconds = 0.0;
  for (int k = 64; k <= 65536; k *= 2) {
    if (k > 64 && last_seconds * 2.0 > 60.0) break;
    const Timer one;
    lab14::ContactStepper stepper = make_contact_stepper(scene, "contact-constrained", k);
    Particles state = start;
    const lab14::StepReport report = stepper.step(state);
    last_seconds = one.seconds();
    if (!report.problem.empty()) throw std::runtime_error(scene.name + ": the reference step: " + report.problem);
    ref.after = state;
    ref.iterations = k;
    ref.contacts_found = static_cast<int>(report.contacts.size());
    ref.contacts_active = report.active;
    if (k > 64) {
      ref.change = rms_distance(state.x, previous.x);
      if (ref.change <= 1e-13) break;
    }
    previous = state;
  }
  ref.displacement = rms_distance(ref.after.x, start.x);
  ref.seconds = timer.seconds();
  return ref;
}

std::vector<int> contact_iteration_counts(bool quick) {
  return quick ? std::vector<int>{1, 3, 10, 30} : std::vector<int>{1, 2, 5, 10, 20, 50, 100, 200, 500, 1000};
}

std::string time_text(double seconds) {
  char text[32];
  if (seconds < 0.9995e-3) std::snprintf(text, sizeof text, "%.3g us", seconds * 1e6);
  else if (seconds < 0.9995) std::snprintf(text, sizeof text, "%.3g ms", seconds * 1e3);
  else std::snprintf(text, sizeof text, "%.3g s", seconds);
  return text;
}

struct ContactRun {
  std::string method;
  int iterations = 0, repeats = 0, contacts_found = 0, contacts_active = 0, moved_back = 0;
  double step_seconds = 0.0, distance = 0.0, distance_max = 0.0, relative_distance = 0.0, penetration = 0.0;
  std::string problem;
};

}  // namespace

void check_contact_trade(const ContactTradeOptions& options) {
  for (const std::string& name : options.scenes) drape_scene(name);
}

void run_contact_trade(const ContactTradeOptions& options) {
  const std::vector<MethodInfo>& all = contact_methods();
  std::vector<std::string> methods;
  for (const MethodInfo& method : all) {
    if (options.methods.empty() ||
        std::find(options.methods.begin(), options.methods.end(), method.name) != options.methods.end()) {
      methods.push_back(method.name);
    }
  }
  CsvTable table({"scene", "particles", "method", "iterations", "step_seconds", "repeats", "distance_rms",
                  "distance_max", "relative_distance", "max_penetration", "contacts_found", "contacts_active",
                  "moved_back", "reference_iterations", "reference_change", "reference_displacement_rms",
                  "warmup_steps", "problem"});
  for (const std::string& name : options.scenes) {
    const Scene scene = drape_scene(name);
    // The shared start: `warmup` constrained steps (K = 20) from the flat
    // cloth, so that it lies on the sphere with contacts that push, stick and slide.
    Particles start = scene.particles;
    {
      lab14::ContactStepper warm = make_contact_stepper(scene, "contact-constrained", 20);
      for (int w = 0; w < options.warmup; ++w) {
        const lab14::StepReport report = warm.step(start);
        if (!report.problem.empty()) throw std::runtime_error(scene.name + ": warm-up: " + report.problem);
      }
    }
    const ContactReference ref = reference_step(scene, start);
    std::printf("%-12s contact: %lld particles, %d warm-up steps; reference: the constrained step at K = %d "
                "(change from K/2 %.1e m RMS, step displacement %.3e m RMS, %d contacts found, %d active, %s)\n",
                scene.name.c_str(), static_cast<long long>(scene.particles.size()), options.warmup, ref.iterations,
                ref.change, ref.displacement, ref.contacts_found, ref.contacts_active, time_text(ref.seconds).c_str());
    std::printf("  %-20s %6s %10s %12s %12s %12s %7s %7s\n", "method", "K", "step", "rel. dist.", "max dist. m",
                "penetr. m", "found", "active");
    std::vector<ContactRun> runs;
    for (const std::string& method : methods) {
      for (const int k : contact_iteration_counts(options.quick)) {
        ContactRun r;
        r.method = method;
        r.iterations = k;
        lab14::ContactStepper stepper = make_contact_stepper(scene, method, k);
        std::vector<double> times;
        double timed = 0.0;
        for (int rep = 0; rep < 200 && (rep < options.repeats || timed < 0.02); ++rep) {
          Particles state = start;
          const Timer step_timer;
          const lab14::StepReport report = stepper.step(state);
          times.push_back(step_timer.seconds());
          timed += times.back();
          if (rep == 0) {
            r.problem = report.problem;
            r.contacts_found = static_cast<int>(report.contacts.size());
            r.contacts_active = report.active;
            r.moved_back = report.moved_back;
            r.distance = rms_distance(state.x, ref.after.x);
            r.distance_max = (state.x - ref.after.x).colwise().norm().maxCoeff();
            r.relative_distance = ref.displacement > 0.0 ? r.distance / ref.displacement : 0.0;
            r.penetration = lab14::max_penetration(state.x, state.inv_mass, scene.colliders);
          }
          if (!report.problem.empty() || times.front() > 2.0 * options.step_cap) break;
        }
        r.repeats = static_cast<int>(times.size());
        r.step_seconds = median(times);
        runs.push_back(r);
        table.add_row({scene.name, static_cast<long long>(scene.particles.size()), method, static_cast<long long>(k),
                       r.step_seconds, static_cast<long long>(r.repeats), r.distance, r.distance_max,
                       r.relative_distance, r.penetration, static_cast<long long>(r.contacts_found),
                       static_cast<long long>(r.contacts_active), static_cast<long long>(r.moved_back),
                       static_cast<long long>(ref.iterations), ref.change, ref.displacement,
                       static_cast<long long>(options.warmup), csv_text(r.problem)});
        std::printf("  %-20s %6d %10s %12.3e %12.3e %12.3e %7d %7d%s\n", method.c_str(), k,
                    time_text(r.step_seconds).c_str(), r.relative_distance, r.distance_max, r.penetration,
                    r.contacts_found, r.contacts_active, r.problem.empty() ? "" : ("  " + r.problem).c_str());
        std::fflush(stdout);
        if (r.step_seconds > options.step_cap || !r.problem.empty()) break;
      }
    }
    // The fastest run to each target of the relative distance.
    for (const double target : {1e-2, 1e-3}) {
      const ContactRun* best = nullptr;
      for (const ContactRun& r : runs) {
        if (r.problem.empty() && r.relative_distance <= target && (!best || r.step_seconds < best->step_seconds)) {
          best = &r;
        }
      }
      std::printf("  fastest to a distance <= %.0e of the step's displacement: %s\n", target,
                  best ? (best->method + " K=" + std::to_string(best->iterations) + " " +
                          time_text(best->step_seconds)).c_str()
                       : "none reached");
    }
  }
  table.write(join_path(options.out, "trade_contact.csv"));
}

#else

void check_contact_trade(const ContactTradeOptions&) {
  throw std::runtime_error("trade: the drape-N scenes need lab 14's reference, which this build does not have");
}

void run_contact_trade(const ContactTradeOptions&) {
  throw std::runtime_error("trade: the drape-N scenes need lab 14's reference, which this build does not have");
}

#endif

}  // namespace cl::bench
