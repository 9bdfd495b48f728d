// common/driver.h: the scenes of a sweep, its runs costliest first and shared
// among threads (every run done, the first failure thrown again), an
// experiment's refusals, a hard spring's refusal and the settle status; common/cli.h's lab_defaults;
// common/csv.h's cell_if.
#include <atomic>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/catch.h"

#include "common/csv.h"
#include "common/driver.h"
#include "common/output.h"
#include "tests/support/scratch.h"

namespace {

// A scene file in `scratch`; its path.
std::string scene_file(const cl::test::ScratchDir& scratch, const std::string& name, int steps) {
  const std::string path = scratch.file(name + ".json");
  cl::write_file_atomic(path, R"({"name": ")" + name + R"(", "dt": 0.01, "steps": )" + std::to_string(steps) +
                                  R"(, "particles": [{"x": [0, 0, 0]}, {"x": [1, 0, 0]}], "springs": [{"i": 0, "j": 1}]})");
  return path;
}

}  // namespace

TEST_CASE("load_scenes loads the sweep's scenes in order, or --scene alone, with --steps applied", "[common][driver]") {
  const cl::test::ScratchDir scratch("driver_kit");
  cl::CommonOptions options;
  options.scene = scene_file(scratch, "alone", 5);
  options.steps = 3;
  const std::vector<cl::Scene> alone = cl::load_scenes(options, {}, ".");
  REQUIRE(alone.size() == 1);
  CHECK(alone[0].name == "alone");
  CHECK(alone[0].steps == 3);

  const std::vector<cl::Scene> both =
      cl::load_scenes(options, {scene_file(scratch, "first", 5), scene_file(scratch, "second", 6)}, ".");
  REQUIRE(both.size() == 2);
  CHECK(both[0].name == "first");
  CHECK(both[1].name == "second");
  CHECK(both[1].steps == 3);

  CHECK_THROWS_AS(cl::load_scenes(options, {scratch.file("no_such_scene.json")}, "."), cl::InputError);
  // An unknown name is the fault of the flag that gave it.
  CHECK_THROWS_WITH(cl::load_scenes(options, {"driver-kit-no-such-name"}, "."),
                    Catch::Matchers::StartsWith("--sweep-scenes: no scene named 'driver-kit-no-such-name'"));
  options.scene = "driver-kit-no-such-name";
  CHECK_THROWS_WITH(cl::load_scenes(options, {}, "."), Catch::Matchers::StartsWith("--scene: no scene named"));
}

TEST_CASE("costliest_first orders by cost, ties in their order", "[common][driver]") {
  CHECK(cl::costliest_first({}).empty());
  CHECK(cl::costliest_first({1.0, 3.0, 2.0, 3.0}) == std::vector<std::size_t>{1, 3, 2, 0});
}

TEST_CASE("run_shared runs every index once and throws the first failure after all ran", "[common][driver]") {
  std::vector<int> ran(50, 0);
  std::vector<std::size_t> order;
  for (std::size_t r = 0; r < ran.size(); ++r) order.push_back(ran.size() - 1 - r);
  cl::run_shared(order, [&](std::size_t r) { ++ran[r]; });
  CHECK(ran == std::vector<int>(50, 1));

  std::atomic<int> done{0};
  CHECK_THROWS_WITH(cl::run_shared(order,
                                   [&](std::size_t r) {
                                     ++done;
                                     if (r == 7) throw std::runtime_error("run 7 failed");
                                   }),
                    "run 7 failed");
  CHECK(done == 50);
}

TEST_CASE("lab_defaults sets the scene, the method and its choices, and leaves the rest", "[common][driver]") {
  const cl::CommonOptions plain = cl::lab_defaults("curtain-16");
  CHECK(plain.scene == "curtain-16");
  CHECK(plain.method.empty());
  CHECK(plain.methods.empty());
  CHECK(plain.iterations == cl::CommonOptions{}.iterations);
  const cl::CommonOptions with = cl::lab_defaults("chain", "schur", {"kkt", "schur"});
  CHECK(with.method == "schur");
  CHECK(with.methods == std::vector<std::string>{"kkt", "schur"});
}

TEST_CASE("refuse_run_flags refuses --frames, then --summary, each with its reason, and an empty reason lets it by",
          "[common][driver]") {
  cl::CommonOptions options;
  CHECK_NOTHROW(cl::refuse_run_flags(options, "not with a sweep", "a sweep writes a CSV"));
  options.frames = 2;
  options.summary = "s.json";
  CHECK_THROWS_MATCHES(cl::refuse_run_flags(options, "not with a sweep", "a sweep writes a CSV"), cl::InputError,
                       Catch::Matchers::Message("--frames: not with a sweep"));
  CHECK_THROWS_MATCHES(cl::refuse_run_flags(options, "", "a sweep writes a CSV"), cl::InputError,
                       Catch::Matchers::Message("--summary: a sweep writes a CSV"));
  CHECK_NOTHROW(cl::refuse_run_flags(options, "", ""));
}

TEST_CASE("settle_status: settled, not settled, or where and why the run diverged", "[common][driver]") {
  CHECK(cl::settle_status("", 12, true) == "settled");
  CHECK(cl::settle_status("", 12, false) == "not settled");
  CHECK(cl::settle_status("strain 12", 7, true) == "diverged at frame 7: strain 12");
}

TEST_CASE("cell_if is the number where it is known and an empty cell where it is not", "[common][driver]") {
  CHECK(cl::cell_if(true, 0.5) == cl::CsvCell{0.5});
  CHECK(cl::cell_if(false, 0.5) == cl::CsvCell{std::string()});
}

TEST_CASE("require_finite_springs names the first hard spring and lets finite ones by", "[common][driver]") {
  const cl::test::ScratchDir scratch("driver_kit_hard");
  cl::CommonOptions options;
  options.scene = scene_file(scratch, "hard", 1);  // its spring has the default stiffness, inf
  cl::Scene scene = cl::load_scenes(options, {}, ".").front();
  CHECK_THROWS_WITH(cl::require_finite_springs(scene, "why"),
                    scene.source + ": springs[0].stiffness: inf is a hard constraint; why");
  scene.springs[0].stiffness = 1e12;
  CHECK_NOTHROW(cl::require_finite_springs(scene, "why"));
}
