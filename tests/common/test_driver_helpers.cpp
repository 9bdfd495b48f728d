// The pieces the lab drivers share: describe and frames_in (common/scene.h),
// the time-stepping summary and its energy and verdict fields
// (common/summary.h), the OBJ frame file (common/obj.h).
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/catch.h"
#include <nlohmann/json.hpp>

#include "common/obj.h"
#include "common/output.h"
#include "common/scene.h"
#include "common/summary.h"
#include "tests/support/scratch.h"

using Catch::Matchers::WithinRel;

namespace {

cl::Scene parse(const std::string& text) { return cl::parse_scene(text, "test.json"); }

std::vector<std::string> keys_of(const nlohmann::ordered_json& object) {
  std::vector<std::string> keys;
  for (const auto& item : object.items()) keys.push_back(item.key());
  return keys;
}

// A moving two-particle scene and a summary of it, as a driver fills one.
cl::Scene two_particles() {
  return parse(R"({"name": "pair", "dt": 0.01, "steps": 7,
                   "particles": [{"x": [0, 0, 0], "v": [1, 2, 3]}, {"x": [1, 0, 0], "v": [4, 5, 6]}],
                   "springs": [{"i": 0, "j": 1}]})");
}

}  // namespace

TEST_CASE("describe counts particles and springs and triangles only when there are some", "[common]") {
  const cl::Scene chain = parse(R"({"name": "rope", "chain": {"links": 5}})");
  CHECK(cl::describe(chain) == "rope (6 particles, 5 springs)");

  const cl::Scene triangle = parse(R"({"name": "tri",
      "particles": [{"x": [0, 0, 0]}, {"x": [1, 0, 0]}, {"x": [0, 1, 0]}],
      "springs": [{"i": 0, "j": 1}, {"i": 1, "j": 2}, {"i": 2, "j": 0}],
      "triangles": [{"i": 0, "j": 1, "k": 2}]})");
  CHECK(cl::describe(triangle) == "tri (3 particles, 3 springs, 1 triangles)");

  for (const int n : {2, 3, 8}) {
    CAPTURE(n);
    const cl::Scene cloth = parse(R"({"name": "cloth", "cloth": {"nx": )" + std::to_string(n) +
                                  R"(, "ny": )" + std::to_string(n) + "}}");
    // A grid of n × n particles has 2 (n − 1)² triangles.
    CHECK(cl::describe(cloth) == "cloth (" + std::to_string(n * n) + " particles, " +
                                     std::to_string(cloth.springs.size()) + " springs, " +
                                     std::to_string(2 * (n - 1) * (n - 1)) + " triangles)");
  }

  const cl::Scene alone = parse(R"({"name": "alone", "particles": [{"x": [0, 0, 0]}]})");
  CHECK(cl::describe(alone) == "alone (1 particles, 0 springs)");
}

TEST_CASE("frames_in rounds seconds over dt to the nearest whole frame", "[common]") {
  for (const double dt : {1.0 / 60.0, 1e-3, 0.25, 0.5}) {
    for (const int frames : {1, 2, 60, 3600}) {
      CAPTURE(dt, frames);
      CHECK(cl::frames_in(frames * dt, dt) == frames);
      CHECK(cl::frames_in((frames + 0.4) * dt, dt) == frames);
      CHECK(cl::frames_in((frames + 0.6) * dt, dt) == frames + 1);
    }
  }
  // An exact half frame (0.625 / 0.25 = 2.5 in binary too) rounds away from zero.
  CHECK(cl::frames_in(0.625, 0.25) == 3);
}

TEST_CASE("frames_in gives at least one frame and at most INT_MAX", "[common]") {
  const double dt = 1.0 / 60.0;
  for (const double seconds : {0.0, -0.0, 0.4 * dt, -1.0, -1e300, -std::numeric_limits<double>::infinity()}) {
    CAPTURE(seconds);
    CHECK(cl::frames_in(seconds, dt) == 1);
  }
  CHECK(cl::frames_in(1e300, dt) == INT_MAX);
  CHECK(cl::frames_in(std::numeric_limits<double>::infinity(), dt) == INT_MAX);
  CHECK(cl::frames_in(1e9, 1e-9) == INT_MAX);
}

TEST_CASE("frames_in refuses a NaN time and a dt that is not finite and positive", "[common]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(cl::frames_in(nan, 0.01), std::invalid_argument);
  for (const double dt : {0.0, -0.01, nan, inf}) {
    CAPTURE(dt);
    CHECK_THROWS_AS(cl::frames_in(1.0, dt), std::invalid_argument);
  }
}

TEST_CASE("stepping_summary fills the contract's common fields in their order", "[common]") {
  const cl::Scene scene = two_particles();
  cl::Particles state = scene.particles;
  state.x(1, 0) = 0.5;  // a final state that is not the scene's start
  cl::StrainStats strain;
  strain.max = 0.125;
  strain.rms = 0.0625;
  cl::RunSummary summary = cl::stepping_summary("labXX", "some-method", scene, state, strain, 2.5);
  CHECK_FALSE(summary.iterations);
  CHECK(summary.extra.empty());

  nlohmann::ordered_json json = cl::to_json(summary);
  CHECK(keys_of(json) == std::vector<std::string>{"lab", "method", "scene", "dt", "steps", "positions", "velocities",
                                                  "max_strain_error", "seconds"});
  CHECK(json["lab"] == "labXX");
  CHECK(json["method"] == "some-method");
  CHECK(json["scene"] == "pair");
  CHECK(json["dt"].get<double>() == scene.dt);
  CHECK(json["steps"] == 7);
  CHECK(json["positions"][0][1].get<double>() == 0.5);
  CHECK(json["positions"][1][0].get<double>() == 1.0);
  CHECK(json["velocities"][1][2].get<double>() == 6.0);
  CHECK(json["max_strain_error"].get<double>() == 0.125);
  CHECK(json["seconds"].get<double>() == 2.5);

  summary.iterations = 12;  // a lab that iterates: after steps, as the contract orders it
  json = cl::to_json(summary);
  CHECK(keys_of(json) == std::vector<std::string>{"lab", "method", "scene", "dt", "steps", "iterations",
                                                  "positions", "velocities", "max_strain_error", "seconds"});
}

TEST_CASE("add_energies appends the energies in order, elastic only when given", "[common]") {
  const double kinetic = 0.75, potential = -3.5, elastic = 0.125, start = -2.0;
  cl::RunSummary summary;
  summary.extra["own"] = 1;
  cl::add_energies(summary, kinetic, potential, std::nullopt, start);
  CHECK(keys_of(summary.extra) ==
        std::vector<std::string>{"own", "kinetic_energy", "potential_energy", "total_energy", "total_energy_start"});
  CHECK(summary.extra["total_energy"].get<double>() == kinetic + potential);
  CHECK(summary.extra["total_energy_start"].get<double>() == start);

  cl::RunSummary with_elastic;
  cl::add_energies(with_elastic, kinetic, potential, elastic, start);
  CHECK(keys_of(with_elastic.extra) == std::vector<std::string>{"kinetic_energy", "potential_energy", "elastic_energy",
                                                                "total_energy", "total_energy_start"});
  CHECK_THAT(with_elastic.extra["total_energy"].get<double>(), WithinRel(kinetic + potential + elastic, 1e-15));
  CHECK(with_elastic.extra["elastic_energy"].get<double>() == elastic);

  cl::RunSummary total_only;
  cl::add_total_energy(total_only, 1.5, 2.5);
  CHECK(keys_of(total_only.extra) == std::vector<std::string>{"total_energy", "total_energy_start"});
  CHECK(total_only.extra["total_energy"].get<double>() == 1.5);
}

TEST_CASE("add_divergence writes diverged and, only when it did, where and why", "[common]") {
  cl::RunSummary fine;
  cl::add_divergence(fine, "", "diverged_at_frame", 17);
  CHECK(keys_of(fine.extra) == std::vector<std::string>{"diverged"});
  CHECK(fine.extra["diverged"] == false);

  for (const std::string at_key : {"diverged_at_frame", "diverged_at_step"}) {
    CAPTURE(at_key);
    cl::RunSummary bad;
    cl::add_divergence(bad, "positions are not finite", at_key, 17);
    CHECK(keys_of(bad.extra) == std::vector<std::string>{"diverged", at_key, "problem"});
    CHECK(bad.extra["diverged"] == true);
    CHECK(bad.extra[at_key] == 17);
    CHECK(bad.extra["problem"] == "positions are not finite");
  }
}

TEST_CASE("an OBJ frame is named by its zero-padded number and says what it is", "[common]") {
  const cl::test::ScratchDir scratch("obj_frame");
  const std::filesystem::path dir = scratch.path();
  const cl::Scene scene = two_particles();
  cl::write_frame_obj(dir.string(), "labXX", scene, scene.particles.x, 42, 0.5);
  std::ifstream file(dir / "frame_000042.obj");
  REQUIRE(file.good());
  std::string first, line;
  std::getline(file, first);
  CHECK(first == "# labXX scene pair frame 42 time " + cl::format_double(0.5));
  int vertices = 0, lines = 0;
  while (std::getline(file, line)) {
    vertices += line.rfind("v ", 0) == 0;
    lines += line.rfind("l ", 0) == 0;
  }
  CHECK(vertices == 2);
  CHECK(lines == 1);  // no triangles: the spring as a line
}

TEST_CASE("add_stop_outcome writes diverged and the failure, and only for a stopped run its outcome and step",
          "[common]") {
  cl::RunSummary fine;
  cl::add_stop_outcome(fine, "", "singular", 17);
  CHECK(keys_of(fine.extra) == std::vector<std::string>{"diverged", "singular"});
  CHECK(fine.extra["diverged"] == false);
  CHECK(fine.extra["singular"] == false);

  cl::RunSummary diverged;
  cl::add_stop_outcome(diverged, "diverged: positions are not finite", "failed", 3);
  CHECK(keys_of(diverged.extra) == std::vector<std::string>{"diverged", "failed", "outcome", "stopped_at_step"});
  CHECK(diverged.extra["diverged"] == true);
  CHECK(diverged.extra["failed"] == false);
  CHECK(diverged.extra["outcome"] == "diverged: positions are not finite");
  CHECK(diverged.extra["stopped_at_step"] == 3);

  cl::RunSummary singular;
  cl::add_stop_outcome(singular, "singular: J W J^T", "singular", 1);
  CHECK(singular.extra["diverged"] == false);
  CHECK(singular.extra["singular"] == true);
  CHECK(singular.extra["stopped_at_step"] == 1);
}
