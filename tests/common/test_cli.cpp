// The shared command line: scene lookup and the exit-code mapping of run_main.
#include <filesystem>
#include <map>

#include <CLI/CLI.hpp>
#include <catch2/catch.hpp>

#include "common/cli.h"
#include "common/not_implemented.h"
#include "common/timer.h"

using Catch::Matchers::Contains;
using Catch::Matchers::EndsWith;

namespace {
const std::string kLab01Scenes = std::string(CL_SOURCE_DIR) + "/labs/lab01_single_spring/scenes";

int run_with(std::vector<std::string> arguments, const std::function<int()>& body) {
  CLI::App app{"test", "probe"};
  cl::CommonOptions options;
  options.scene = "two-particles";
  cl::add_common_options(app, options, cl::kFlagScene | cl::kFlagDt);
  arguments.insert(arguments.begin(), "probe");
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  return cl::run_main(app, static_cast<int>(argv.size()), argv.data(), body);
}
}  // namespace

TEST_CASE("not_implemented names the function and the course-relative file", "[common][cli]") {
  try {
    cl::not_implemented("project_distance", CL_SOURCE_DIR "/labs/lab01_single_spring/single_spring.cpp");
    FAIL("not_implemented returned");
  } catch (const cl::NotImplemented& error) {
    CHECK(error.function() == "project_distance");
    CHECK(error.file() == "labs/lab01_single_spring/single_spring.cpp");
    CHECK_THAT(std::string(error.what()), Contains("project_distance is not implemented yet"));
  }
}

TEST_CASE("scene names resolve to shipped files, paths stay paths", "[common][cli]") {
  CHECK_THAT(cl::resolve_scene_path("two-particles", kLab01Scenes), EndsWith("lab01_single_spring/scenes/two-particles.json"));
  CHECK(cl::resolve_scene_path("some/dir/file.json", kLab01Scenes) == "some/dir/file.json");
  try {
    cl::resolve_scene_path("no-such-scene", kLab01Scenes);
    FAIL("an unknown scene name was accepted");
  } catch (const cl::InputError& error) {
    CHECK_THAT(std::string(error.what()), Contains("no scene named 'no-such-scene'"));
    CHECK_THAT(std::string(error.what()), Contains("two-particles"));
  }
}

TEST_CASE("run_main maps each outcome to its exit code", "[common][cli]") {
  CHECK(run_with({}, [] { return 0; }) == 0);
  CHECK(run_with({"--dt", "0.01"}, [] { return 0; }) == 0);
  CHECK(run_with({"--dt", "-1"}, [] { return 0; }) == 2);
  CHECK(run_with({"--dt", "inf"}, [] { return 0; }) == 2);
  CHECK(run_with({"--bogus"}, [] { return 0; }) == 2);
  CHECK(run_with({}, []() -> int { throw cl::InputError("bad.json: springs[0].i: out of range"); }) == 2);
  CHECK(run_with({}, []() -> int { cl::not_implemented("f", "labs/x.cpp"); }) == 3);
  CHECK(run_with({}, []() -> int { throw std::runtime_error("boom"); }) == 1);
}

TEST_CASE("the timer counts forward", "[common][cli]") {
  const cl::Timer timer;
  const double first = timer.seconds();
  CHECK(first >= 0.0);
  CHECK(timer.seconds() >= first);
}

TEST_CASE("scene names are unique across labs, so --scene NAME is never ambiguous", "[common][cli]") {
  namespace fs = std::filesystem;
  std::map<std::string, std::string> owner;
  for (const auto& lab : fs::directory_iterator(fs::path(CL_SOURCE_DIR) / "labs")) {
    for (const std::string& name : cl::list_scene_names((lab.path() / "scenes").string())) {
      CAPTURE(name, lab.path().filename().string());
      const auto [where, inserted] = owner.emplace(name, lab.path().filename().string());
      CAPTURE(where->second);
      CHECK(inserted);
    }
  }
  CHECK(owner.count("two-particles") == 1);
}

TEST_CASE("every shipped scene loads", "[common][cli]") {
  namespace fs = std::filesystem;
  int count = 0;
  for (const auto& lab : fs::directory_iterator(fs::path(CL_SOURCE_DIR) / "labs")) {
    const fs::path dir = lab.path() / "scenes";
    for (const std::string& name : cl::list_scene_names(dir.string())) {
      CAPTURE((dir / (name + ".json")).string());
      CHECK_NOTHROW(cl::load_scene((dir / (name + ".json")).string()));
      ++count;
    }
  }
  CHECK(count > 0);
}

TEST_CASE("finite_in accepts [low, high] and rejects nan, inf and text", "[common][cli]") {
  const CLI::Validator check = cl::finite_in(0.0, 2.0);
  for (std::string good : {"0", "2", "1.5"}) {
    CAPTURE(good);
    CHECK(check(good).empty());
  }
  for (std::string bad : {"-0.1", "2.5", "nan", "inf", "1x", ""}) {
    CAPTURE(bad);
    CHECK_FALSE(check(bad).empty());
  }
}
