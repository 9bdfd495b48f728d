// The shared command line: scene lookup and the exit-code mapping of run_main.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>

#include <unistd.h>

#include <CLI/CLI.hpp>
#include "tests/support/catch.h"

#include "common/cli.h"
#include "common/not_implemented.h"
#include "common/timer.h"
#include "tests/support/scene_promises.h"

using cl::test::ContainsText;
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
    CHECK_THAT(std::string(error.what()), ContainsText("project_distance is not implemented yet"));
  }
}

TEST_CASE("scene names resolve to shipped files, paths stay paths", "[common][cli]") {
  CHECK_THAT(cl::resolve_scene_path("two-particles", kLab01Scenes), EndsWith("lab01_single_spring/scenes/two-particles.json"));
  CHECK(cl::resolve_scene_path("some/dir/file.json", kLab01Scenes) == "some/dir/file.json");
  try {
    cl::resolve_scene_path("no-such-scene", kLab01Scenes);
    FAIL("an unknown scene name was accepted");
  } catch (const cl::InputError& error) {
    CHECK_THAT(std::string(error.what()), ContainsText("no scene named 'no-such-scene'"));
    CHECK_THAT(std::string(error.what()), ContainsText("two-particles"));
  }
}

TEST_CASE("an unknown scene name lists what the lab can load", "[common][cli]") {
  // A lab with scenes of its own lists them; one without (lab 11 runs lab 06's
  // and lab 04's) lists every lab's, by lab, never an empty list.
  CHECK_THROWS_WITH(cl::resolve_scene_path("nosuch", kLab01Scenes),
                    ContainsText("this lab ships: ") && ContainsText("two-particles"));
  CHECK_THROWS_WITH(cl::resolve_scene_path("nosuch", cl::lab_scene_dir("lab11_acceleration")),
                    ContainsText("lab06_projective_dynamics: ") && ContainsText("pd-curtain-32") &&
                        ContainsText("lab04_pbd: ") && !ContainsText("ships: )"));
  CHECK_THROWS_WITH(cl::resolve_scene_path("nosuch", kLab01Scenes, "--sweep-scenes"),
                    Catch::Matchers::StartsWith("--sweep-scenes: no scene named 'nosuch'"));
}

TEST_CASE("integer flags say the text is not an integer or which range it is outside", "[common][cli]") {
  const CLI::Validator check = cl::integer_in(1, 16);
  for (std::string good : {"1", "16", "7"}) {
    CAPTURE(good);
    CHECK(check(good).empty());
  }
  std::string text = "abc";
  CHECK(check(text) == "'abc' is not an integer");
  text = "1.5";
  CHECK(check(text) == "'1.5' is not an integer");
  text = "";
  CHECK(check(text) == "'' is not an integer");
  text = "17";
  CHECK(check(text) == "17 is not in [1, 16]");
  text = "99999999999999999999";
  CHECK(check(text) == "99999999999999999999 is not in [1, 16]");
}

namespace {
// Runs a CommandLine with --method (pd, pd-chebyshev) and --rho (pd-chebyshev
// only), --iterations and an int --seed without a range; the exit code and stderr.
std::pair<int, std::string> run_line(std::vector<std::string> arguments) {
  cl::CommandLine line{"test", "probe"};
  cl::CommonOptions options = cl::lab_defaults("two-particles", "pd", {"pd", "pd-chebyshev"});
  cl::add_common_options(line, options, cl::kFlagMethod | cl::kFlagIterations);
  double rho = 0.0;
  int seed = 0;
  line.add_option("--rho", rho, "rho").non_negative().only_for_methods({"pd-chebyshev"});
  line.add_option("--seed", seed, "seed");
  arguments.insert(arguments.begin(), "probe");
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  std::ostringstream captured;
  std::streambuf* const saved = std::cerr.rdbuf(captured.rdbuf());
  const int code = cl::run_main(line, static_cast<int>(argv.size()), argv.data(), [] { return 0; });
  std::cerr.rdbuf(saved);
  return {code, captured.str()};
}
}  // namespace

TEST_CASE("a flag the chosen method does not use is refused in one line", "[common][cli]") {
  CHECK(run_line({"--method", "pd-chebyshev", "--rho", "0.5"}).first == 0);
  CHECK(run_line({"--method", "pd"}).first == 0);
  const auto [code, text] = run_line({"--method", "pd", "--rho", "0.5"});
  CHECK(code == 2);
  CHECK(text == "probe: --rho: --method pd does not use it (only pd-chebyshev does)\n");
  // The default method counts as chosen.
  CHECK(run_line({"--rho", "0.5"}).first == 2);
  // Integer flags, with a range and without one.
  CHECK(run_line({"--iterations", "abc"}).second == "probe: --iterations: 'abc' is not an integer (see --help)\n");
  CHECK(run_line({"--seed", "1x"}).second == "probe: --seed: '1x' is not an integer (see --help)\n");
  CHECK(run_line({"--seed", "12"}).first == 0);
}

TEST_CASE("an empty value and an empty list item are refused in one line naming the item", "[common][cli]") {
  // CLI11 drops an empty item of a delimited list and takes "" for a string as
  // given: "--ks 1,,2" would run K = 1, 2, and "--name ''" as if absent.
  auto run = [](std::vector<std::string> arguments) {
    cl::CommandLine line{"test", "probe"};
    std::vector<int> ks;
    std::string name;
    bool flag = false;
    line.add_option("--ks", ks, "a list").delimiter(',');
    line.add_option("--name", name, "a word");
    line.add_flag("--flag", flag, "a flag");
    arguments.insert(arguments.begin(), "probe");
    std::vector<char*> argv;
    for (std::string& argument : arguments) argv.push_back(argument.data());
    std::ostringstream captured;
    std::streambuf* const saved = std::cerr.rdbuf(captured.rdbuf());
    bool ran = false;
    const int code = cl::run_main(line, static_cast<int>(argv.size()), argv.data(), [&] {
      ran = true;
      return 0;
    });
    std::cerr.rdbuf(saved);
    return std::make_tuple(code, captured.str(), ran, ks);
  };
  const auto [ok_code, ok_text, ok_ran, ok_ks] = run({"--ks", "1,2", "--name", "a", "--flag"});
  CHECK(ok_code == 0);
  CHECK(ok_ran);
  CHECK(ok_ks == std::vector<int>{1, 2});
  const std::vector<std::pair<std::vector<std::string>, std::string>> refused{
      {{"--ks", "1,,2"}, "probe: --ks[1]: empty (in '1,,2'; a list is VALUE,VALUE...)\n"},
      {{"--ks", ",2"}, "probe: --ks[0]: empty (in ',2'; a list is VALUE,VALUE...)\n"},
      {{"--ks=3,"}, "probe: --ks[1]: empty (in '3,'; a list is VALUE,VALUE...)\n"},
      {{"--ks", ""}, "probe: --ks: empty (give a value; see --help)\n"},
      {{"--name", ""}, "probe: --name: empty (give a value; see --help)\n"},
      {{"--name="}, "probe: --name: empty (give a value; see --help)\n"}};
  for (const auto& [arguments, line] : refused) {
    CAPTURE(arguments);
    const auto [code, text, ran, ks] = run(arguments);
    CHECK(code == 2);
    CHECK(!ran);
    CHECK(text == line);
  }
}

TEST_CASE("a range given to a common integer flag replaces the common one", "[common][cli]") {
  // Lab 14 takes --iterations in [1, 100000]: its refusal and --help must
  // state that range, not the common flag's [0, 100000000] checked first.
  for (const char* given : {"0", "6", "-3"}) {
    CAPTURE(given);
    cl::CommandLine line{"test", "probe"};
    cl::CommonOptions options = cl::lab_defaults("two-particles", "pd", {"pd"});
    cl::add_common_options(line, options, cl::kFlagIterations);
    line.get_option("--iterations").range(1, 5);
    CHECK_THAT(line.app().help(), ContainsText("[1, 5]") && !ContainsText("100000000"));
    std::vector<std::string> arguments{"probe", "--iterations", given};
    std::vector<char*> argv;
    for (std::string& argument : arguments) argv.push_back(argument.data());
    std::ostringstream captured;
    std::streambuf* const saved = std::cerr.rdbuf(captured.rdbuf());
    const int code = cl::run_main(line, static_cast<int>(argv.size()), argv.data(), [] { return 0; });
    std::cerr.rdbuf(saved);
    CHECK(code == 2);
    CHECK(captured.str() == "probe: --iterations: " + std::string(given) + " is not in [1, 5] (see --help)\n");
  }
}

namespace {
// A CommandLine with a mode (--convergence, which alone reads --warmup) and a
// run-only --steps; the exit code, stdout and stderr of one call, whose body
// records whether it got past start_run.
struct Outcome {
  int code;
  std::string out, err;
  bool worked;
};

Outcome run_modes(std::vector<std::string> arguments) {
  cl::CommandLine line{"test", "probe"};
  cl::CommonOptions options = cl::lab_defaults("two-particles");
  cl::add_common_options(line, options, cl::kFlagSteps | cl::kFlagOut);
  bool convergence = false;
  int warmup = 0;
  line.add_flag("--convergence", convergence, "a mode");
  line.add_option("--warmup", warmup, "read by --convergence only");
  line.modes({{"--convergence", {"--warmup"}}}, {"--steps"});
  arguments.insert(arguments.begin(), "probe");
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  std::ostringstream out, err;
  std::streambuf* const saved_out = std::cout.rdbuf(out.rdbuf());
  std::streambuf* const saved_err = std::cerr.rdbuf(err.rdbuf());
  bool worked = false;
  const int code = cl::run_main(line, static_cast<int>(argv.size()), argv.data(), [&] {
    (void)cl::load_scene_for(options, kLab01Scenes);
    cl::start_run(options);
    worked = true;
    return 0;
  });
  std::cout.rdbuf(saved_out);
  std::cerr.rdbuf(saved_err);
  return {code, out.str(), err.str(), worked};
}
}  // namespace

TEST_CASE("the check flag loads the scene, says what would run and stops where the run starts", "[common][cli]") {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("cl-check-" + std::to_string(::getpid()));
  std::filesystem::remove_all(folder);
  const Outcome checked = run_modes({"--check", "--out", folder.string()});
  CHECK(checked.code == 0);
  CHECK_FALSE(checked.worked);
  CHECK_THAT(checked.out, ContainsText("probe: check: ok, would run two-particles") && ContainsText("writes " + folder.string()));
  CHECK(checked.err.empty());
  CHECK_FALSE(std::filesystem::exists(folder));
  // Without --check the same call makes the folder and does the work.
  const Outcome ran = run_modes({"--out", folder.string()});
  CHECK(ran.code == 0);
  CHECK(ran.worked);
  CHECK(std::filesystem::is_directory(folder));
  std::filesystem::remove_all(folder);
  // A refusal under --check is the run's refusal: exit 2, one line, nothing on stdout.
  const Outcome refused = run_modes({"--check", "--steps", "-3"});
  CHECK(refused.code == 2);
  CHECK(refused.out.empty());
  CHECK_FALSE(refused.worked);
}

TEST_CASE("a flag the chosen mode does not read is refused in one line", "[common][cli]") {
  CHECK(run_modes({"--convergence", "--warmup", "3"}).code == 0);
  CHECK(run_modes({"--steps", "3"}).code == 0);
  const Outcome unread = run_modes({"--warmup", "3"});
  CHECK(unread.code == 2);
  CHECK(unread.err == "probe: --warmup: a run does not read it (only --convergence does)\n");
  const Outcome run_only = run_modes({"--convergence", "--steps", "3"});
  CHECK(run_only.code == 2);
  CHECK(run_only.err == "probe: --steps: --convergence does not read it (only a run does)\n");
}

TEST_CASE("the check line names --method only in a mode that reads it", "[common][cli]") {
  auto check_line = [](std::vector<std::string> arguments) {
    cl::CommandLine line{"test", "probe"};
    cl::CommonOptions options = cl::lab_defaults("two-particles");
    options.method = "pd";
    cl::add_common_options(line, options, cl::kFlagMethod);
    bool convergence = false;
    line.add_flag("--convergence", convergence, "a mode that runs every method");
    line.modes({{"--convergence", {}}}, {"--method"});
    arguments.insert(arguments.begin(), {"probe", "--check"});
    std::vector<char*> argv;
    for (std::string& argument : arguments) argv.push_back(argument.data());
    std::ostringstream out;
    std::streambuf* const saved_out = std::cout.rdbuf(out.rdbuf());
    const int code = cl::run_main(line, static_cast<int>(argv.size()), argv.data(), [&] {
      (void)cl::load_scene_for(options, kLab01Scenes);
      cl::start_run(options);
      return 0;
    });
    std::cout.rdbuf(saved_out);
    CHECK(code == 0);
    return out.str();
  };
  CHECK_THAT(check_line({}), ContainsText(", --method pd"));
  CHECK_THAT(check_line({"--convergence"}), !ContainsText("--method"));
}

TEST_CASE("an unknown option is named and the program's options listed", "[common][cli]") {
  const Outcome unknown = run_modes({"--rho", "0.5"});
  CHECK(unknown.code == 2);
  CHECK_THAT(unknown.err, Catch::Matchers::StartsWith("probe: unknown option --rho (options: ") &&
                              ContainsText("--steps") && ContainsText("--warmup") && ContainsText("--check"));
  CHECK(std::count(unknown.err.begin(), unknown.err.end(), '\n') == 1);
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

TEST_CASE("the dt and steps flags hold the scene's ranges", "[common][cli][limits]") {
  std::ostringstream captured;
  std::streambuf* const saved = std::cerr.rdbuf(captured.rdbuf());
  const int huge = run_with({"--dt", "1e300"}, [] { return 0; });
  const int tiny = run_with({"--dt", "1e-300"}, [] { return 0; });
  const int ends = run_with({"--dt", "1e-9"}, [] { return 0; }) + run_with({"--dt", "10"}, [] { return 0; });
  std::cerr.rdbuf(saved);
  CHECK(huge == 2);
  CHECK(tiny == 2);
  CHECK(ends == 0);
  std::istringstream lines(captured.str());
  std::string line;
  for (const char* value : {"1e300", "1e-300"}) {
    REQUIRE(std::getline(lines, line));
    CHECK_THAT(line, ContainsText("--dt: must be in [1e-9, 10] s (got " + std::string(value) + ")"));
  }
  CHECK_FALSE(std::getline(lines, line));  // one line each, and none for the range's ends
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
      std::string broken = "(refused)";
      CHECK_NOTHROW(broken = cl::test::broken_promise(cl::load_scene((dir / (name + ".json")).string())));
      CHECK(broken.empty());  // inside every range of limits (common/scene.h)
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

TEST_CASE("a lab that does not model colliders refuses a scene with colliders", "[common][cli]") {
  cl::CommonOptions options;
  options.scene = "drape-sphere";  // lab 14's, found by name from any lab
  const std::string lab04 = std::string(CL_SOURCE_DIR) + "/labs/lab04_pbd/scenes";
  CHECK_THROWS_WITH(cl::load_scene_for(options, lab04),
                    ContainsText("drape-sphere.json: colliders[0]: this lab does not model colliders"));
  options.models_colliders = true;
  CHECK(cl::load_scene_for(options, lab04).colliders.size() == 2);
  options.scene = "curtain-8";  // without colliders: nothing new to refuse
  options.models_colliders = false;
  CHECK(cl::load_scene_for(options, lab04).colliders.empty());
}
