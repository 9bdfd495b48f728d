// common/trajectory.h: the trajectory ./course view plays. Positions and
// strains are read back from trajectory.bin as the view decodes them and
// compared with what was written, to the quantisation the header states; the
// frame loop keeps exactly the frames it promises; the size cap's advice fits.
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "tests/support/catch.h"
#include <nlohmann/json.hpp>

#include "common/cli.h"
#include "common/frame_loop.h"
#include "common/output.h"
#include "common/trajectory.h"
#include "tests/support/scratch.h"

using cl::test::ContainsText;

namespace {

// Three particles (the first pinned) spanning 3 m, two springs, one triangle.
cl::Scene small_scene() {
  cl::Scene scene;
  scene.name = "small";
  scene.particles.x.resize(3, 3);
  scene.particles.x << 0.0, 3.0, 0.0,  //
      0.0, 0.0, 1.5,                   //
      0.0, 0.0, 0.25;
  scene.particles.v = Eigen::Matrix3Xd::Zero(3, 3);
  scene.particles.inv_mass = Eigen::Vector3d(0.0, 1.0, 1.0);
  scene.springs = {{0, 1, 3.0, cl::kInfiniteStiffness}, {1, 2, 2.0, cl::kInfiniteStiffness}};
  scene.triangles = {{0, 1, 2, 2.25}};
  return scene;
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

std::vector<std::uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Frame k of the file as the view decodes it: x = box_min + q · step.
Eigen::Matrix3Xd decoded_positions(const nlohmann::json& header, const std::vector<std::uint8_t>& data, int k) {
  const int n = header["particles"];
  const nlohmann::json& frame = header["frames"][static_cast<std::size_t>(k)];
  const std::size_t start = static_cast<std::size_t>(k) * header["frame_bytes"].get<std::size_t>();
  Eigen::Matrix3Xd x(3, n);
  for (int p = 0; p < n; ++p) {
    for (int a = 0; a < 3; ++a) {
      const std::size_t at = start + 2 * static_cast<std::size_t>(3 * p + a);
      const int q = data[at] | (data[at + 1] << 8);
      const auto axis = static_cast<std::size_t>(a);
      x(a, p) = frame["box_min"][axis].get<double>() + q * frame["step"][axis].get<double>();
    }
  }
  return x;
}

double decoded_strain(const nlohmann::json& header, const std::vector<std::uint8_t>& data, int k, int spring) {
  const std::size_t start = static_cast<std::size_t>(k) * header["frame_bytes"].get<std::size_t>() +
                            6 * header["particles"].get<std::size_t>() + static_cast<std::size_t>(spring);
  const auto q = static_cast<std::int8_t>(data[start]);
  return q * header["frames"][static_cast<std::size_t>(k)]["strain_scale"].get<double>() / 127.0;
}

}  // namespace

TEST_CASE("a trajectory reads back to the stated quantisation, with its topology and identity",
          "[common][trajectory]") {
  const cl::test::ScratchDir scratch("trajectory_round_trip");
  const std::string dir = scratch.path();
  const cl::Scene scene = small_scene();
  cl::TrajectoryWriter writer(dir, 1, scene, {"lab99_test", "test-method", "total energy", "s"});
  std::vector<Eigen::Matrix3Xd> written;
  for (int f = 0; f < 4; ++f) {
    Eigen::Matrix3Xd x = scene.particles.x;
    x.row(1).array() -= 0.1234567 * f * f;  // falling
    x(0, 2) += 0.01 * std::sin(f + 0.3);
    written.push_back(x);
    writer.add(f, f / 60.0, x, 10.0 - f, "ok");
  }
  writer.finish();

  const nlohmann::json header = read_json(dir + "/trajectory.json");
  const std::vector<std::uint8_t> data = read_bytes(dir + "/trajectory.bin");
  CHECK(header["format"] == "cl-trajectory");
  CHECK(header["lab"] == "lab99_test");
  CHECK(header["method"] == "test-method");
  CHECK(header["scene"] == "small");
  CHECK(header["particles"] == 3);
  CHECK(header["springs"] == nlohmann::json({0, 1, 1, 2}));
  CHECK(header["triangles"] == nlohmann::json({0, 1, 2}));
  // An array of one, said so: in json({0}) the braces may also hold the null
  // pointer constant 0 (json's nullptr_t constructor), which clang picks (null).
  CHECK(header["pinned"] == nlohmann::json::array({0}));
  CHECK(header["frame_count"] == 4);
  CHECK(header["frame_bytes"].get<std::size_t>() % 4 == 0);
  REQUIRE(data.size() == 4 * header["frame_bytes"].get<std::size_t>());
  CHECK(header["bin_bytes"] == data.size());

  const double stated = header["max_position_error"];
  CHECK(stated <= 1e-4);  // the bound: 0.1 mm on a 3 m scene
  for (int k = 0; k < 4; ++k) {
    CAPTURE(k);
    const nlohmann::json& frame = header["frames"][static_cast<std::size_t>(k)];
    CHECK(frame["frame"] == k);
    CHECK(frame["time"].get<double>() == Approx(k / 60.0));
    CHECK(frame["energy"].get<double>() == 10.0 - k);
    const Eigen::Matrix3Xd decoded = decoded_positions(header, data, k);
    const double error = (decoded - written[static_cast<std::size_t>(k)]).cwiseAbs().maxCoeff();
    CAPTURE(error, stated);
    CHECK(error <= stated * (1 + 1e-9));
    const double scale = frame["strain_scale"];
    for (int e = 0; e < 2; ++e) {
      const double exact = cl::signed_strain(written[static_cast<std::size_t>(k)], scene.springs[static_cast<std::size_t>(e)]);
      CAPTURE(e, exact, scale);
      CHECK(std::abs(decoded_strain(header, data, k, e) - exact) <= scale / 254 * (1 + 1e-9));
    }
  }
}

TEST_CASE("a scene's colliders travel in the header, and a scene without writes no colliders key",
          "[common][trajectory]") {
  const cl::test::ScratchDir scratch("trajectory_colliders");
  cl::Scene scene = small_scene();
  const auto header_of = [&] {
    cl::TrajectoryWriter writer(scratch.path(), 1, scene, {"lab99_test", "m", "total energy", "s"});
    writer.add(0, 0.0, scene.particles.x, 0.0, "ok");
    return nlohmann::json::parse(writer.header_text());
  };
  CHECK_FALSE(header_of().contains("colliders"));
  cl::Collider plane, sphere, capsule;
  plane.a = {0.0, -1.0, 0.0};
  plane.normal = {0.0, 1.0, 0.0};
  plane.friction = 0.5;
  sphere.shape = cl::ColliderShape::kSphere;
  sphere.a = {1.0, 2.0, 3.0};
  sphere.radius = 0.25;
  capsule.shape = cl::ColliderShape::kCapsule;
  capsule.a = {0.0, 0.0, 0.0};
  capsule.b = {1.0, 0.0, 0.0};
  capsule.radius = 0.1;
  scene.colliders = {plane, sphere, capsule};
  const nlohmann::json colliders = header_of()["colliders"];
  REQUIRE(colliders.size() == 3);
  CHECK(colliders[0] == nlohmann::json{{"type", "plane"}, {"point", {0.0, -1.0, 0.0}}, {"normal", {0.0, 1.0, 0.0}},
                                       {"friction", 0.5}});
  CHECK(colliders[1] == nlohmann::json{{"type", "sphere"}, {"centre", {1.0, 2.0, 3.0}}, {"radius", 0.25},
                                       {"friction", 0.0}});
  CHECK(colliders[2] == nlohmann::json{{"type", "capsule"}, {"a", {0.0, 0.0, 0.0}}, {"b", {1.0, 0.0, 0.0}},
                                       {"radius", 0.1}, {"friction", 0.0}});
}

TEST_CASE("the frame loop keeps every N-th frame, the last planned one and the frame that stopped",
          "[common][trajectory]") {
  cl::Scene scene = small_scene();
  cl::Particles state = scene.particles;
  const auto step = [&state](int) {
    state.x.row(1).array() -= 0.01;
    return cl::StepVerdict{};
  };
  int stop_at = -1;
  const auto measure = [&stop_at](int frame, double) {
    cl::FrameMeasure measured;
    measured.energy = -frame;
    if (frame == stop_at) measured.problem = "stopped by the test";
    return measured;
  };
  cl::FrameOutput output;
  output.lab = "lab99_test";
  output.scene = &scene;
  output.method = "m";
  output.trajectory_every = 3;

  SECTION("a run that finishes: 0, 3, 6, 9 and the last, 10") {
    const cl::test::ScratchDir scratch("trajectory_every_3");
    output.trajectory_dir = scratch.path();
    const cl::FrameLoopResult result = cl::run_frame_loop(state, step, measure, cl::frame_plan(10, 0.5, 0.0), output);
    CHECK(result.trajectory_frames == 5);
    const nlohmann::json header = read_json(output.trajectory_dir + "/trajectory.json");
    std::vector<int> kept;
    for (const nlohmann::json& frame : header["frames"]) kept.push_back(frame["frame"]);
    CHECK(kept == std::vector<int>{0, 3, 6, 9, 10});
    CHECK(header["frames"][4]["time"].get<double>() == 5.0);
    CHECK(header["frames"][4]["energy"].get<double>() == -10.0);
    CHECK(header["every"] == 3);
  }
  SECTION("a run that stops at frame 4: 0, 3 and 4, with its status") {
    stop_at = 4;
    const cl::test::ScratchDir scratch("trajectory_stopped");
    output.trajectory_dir = scratch.path();
    cl::run_frame_loop(state, step, measure, cl::frame_plan(10, 0.5, 0.0), output);
    const nlohmann::json header = read_json(output.trajectory_dir + "/trajectory.json");
    REQUIRE(header["frame_count"] == 3);
    CHECK(header["frames"][2]["frame"] == 4);
    CHECK_THAT(header["frames"][2]["status"].get<std::string>(), ContainsText("stopped by the test"));
  }
}

TEST_CASE("a frame with a non-finite position is not kept: it is the header's stopped record",
          "[common][trajectory]") {
  const cl::test::ScratchDir scratch("trajectory_non_finite");
  const std::string dir = scratch.path();
  const cl::Scene scene = small_scene();
  cl::TrajectoryWriter writer(dir, 1, scene, {"lab99_test", "m"});
  writer.add(0, 0.0, scene.particles.x, std::numeric_limits<double>::quiet_NaN(), "ok");
  Eigen::Matrix3Xd broken = scene.particles.x;
  broken(1, 2) = std::numeric_limits<double>::infinity();
  writer.add(1, 1.0, broken, 0.0, "diverged: non-finite");
  writer.finish();
  const nlohmann::json header = read_json(dir + "/trajectory.json");
  CHECK(header["frame_count"] == 1);
  CHECK(header["frames"][0]["energy"].is_null());  // NaN: unknown
  CHECK(header["stopped"]["frame"] == 1);
  CHECK(read_bytes(dir + "/trajectory.bin").size() == header["frame_bytes"].get<std::size_t>());
  CHECK_THROWS_AS(cl::TrajectoryWriter(dir, 0, scene, {}), std::invalid_argument);
}

TEST_CASE("the size cap refuses a run too large and its suggested --frames N fits", "[common][trajectory]") {
  cl::Scene scene;
  const int n = 128 * 128;
  scene.particles.x = Eigen::Matrix3Xd::Zero(3, n);
  scene.particles.inv_mass = Eigen::VectorXd::Ones(n);
  scene.springs.assign(4 * n, cl::Spring{0, 1, 1.0, cl::kInfiniteStiffness});
  const int last = 3000;
  const double frame = static_cast<double>(cl::trajectory_frame_bytes(n, scene.springs.size()));
  CHECK(frame == 6.0 * n + 4.0 * n);
  CHECK_NOTHROW(cl::check_trajectory_size(scene, 300, 1));  // 128² over 300 frames fits
  CHECK_NOTHROW(cl::check_trajectory_size(scene, last, 0));  // no trajectory: no check
  std::string message;
  try {
    cl::check_trajectory_size(scene, last, 1);
  } catch (const cl::InputError& error) {
    message = error.what();
  }
  CAPTURE(message);
  REQUIRE_THAT(message, ContainsText("use --frames N with a larger N ("));
  const std::size_t at = message.find("larger N (") + 10;
  const int suggested = std::stoi(message.substr(at));
  CAPTURE(suggested);
  CHECK_NOTHROW(cl::check_trajectory_size(scene, last, suggested));
  CHECK_THROWS_AS(cl::check_trajectory_size(scene, last, suggested - 1), cl::InputError);
  CHECK(cl::trajectory_frames_kept(last, suggested) * frame <= static_cast<double>(cl::kTrajectoryCapBytes));
}

TEST_CASE("a trajectory (--frames) needs --out, checked when the scene is loaded", "[common][trajectory]") {
  cl::CommonOptions options;
  options.scene = "curtain-8";
  options.frames = 2;
  CHECK_THROWS_WITH(cl::load_scene_for(options, cl::lab_scene_dir("lab04_pbd")), ContainsText("--frames: needs --out"));
  const cl::test::ScratchDir scratch("trajectory_unused");
  options.out = scratch.file("unused");
  CHECK_NOTHROW(cl::load_scene_for(options, cl::lab_scene_dir("lab04_pbd")));
}
