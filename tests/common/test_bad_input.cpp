// Every rejection rule of docs/DESIGN.md §3, run through a real lab executable:
// exit code 2, one stderr line naming the file and the field, no output left.
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/support/catch.h"

#include "tests/support/scratch.h"

using cl::test::ContainsText;
using Catch::Matchers::StartsWith;

namespace {

namespace fs = std::filesystem;

struct RunResult {
  int exit_code = -1;
  std::string stderr_text;
};

std::string read(const fs::path& path) {
  std::ifstream file(path);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

// The lab executable the rules are run through: CL_PROBE_EXE, beside this
// program in bin/ (CMakeLists.txt).
fs::path probe() { return fs::read_symlink("/proc/self/exe").parent_path() / CL_PROBE_EXE; }

RunResult run_probe(const std::string& arguments, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  const std::string command = "'" + probe().string() + "' " + arguments + " > /dev/null 2> '" + err.string() + "'";
  const int status = std::system(command.c_str());
  RunResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.stderr_text = read(err);
  return result;
}

// Runs the probe on a scene with `text`, asking for CSV and summary output.
RunResult run_scene(const std::string& text, const fs::path& dir) {
  fs::create_directories(dir);
  std::ofstream(dir / "bad.json") << text;
  return run_probe("--scene '" + (dir / "bad.json").string() + "' --out '" + (dir / "out").string() +
                       "' --summary '" + (dir / "out" / "summary.json").string() + "'",
                   dir);
}

const char* const kTwo = R"("particles": [{"x": [0,0,0]}, {"x": [1,0,0]}])";
const char* const kThree = R"("particles": [{"x": [0,0,0]}, {"x": [1,0,0]}, {"x": [2,0,0]}])";

}  // namespace

TEST_CASE("bad scenes exit 2 with one line naming file and field", "[common][bad-input]") {
  struct Rule {
    const char* what;
    std::string text;
    const char* field;
  };
  const std::vector<Rule> rules{
      {"malformed JSON", R"({"particles": [)", "malformed JSON"},
      {"unknown key", std::string("{") + kTwo + R"(, "colour": "red"})", "colour"},
      {"unknown particle key", R"({"particles": [{"x": [0,0,0], "m": 1}]})", "particles[0].m"},
      {"missing x", R"({"particles": [{"x": [0,0,0]}, {"mass": 1}]})", "particles[1].x"},
      {"non-finite number", R"({"particles": [{"x": [0,0,1e400]}]})", "particles[0].x[2]"},
      {"mass zero", R"({"particles": [{"x": [0,0,0], "mass": 0}]})", "particles[0].mass"},
      {"mass negative", R"({"particles": [{"x": [0,0,0]}, {"x": [1,0,0], "mass": -2}]})", "particles[1].mass"},
      {"rest negative", std::string("{") + kTwo + R"(, "springs": [{"i": 0, "j": 1, "rest": -1}]})",
       "springs[0].rest"},
      {"index out of range", std::string("{") + kTwo + R"(, "springs": [{"i": 0, "j": 1}, {"i": 0, "j": 7}]})",
       "springs[1].j"},
      {"index not an integer", std::string("{") + kTwo + R"(, "springs": [{"i": "0", "j": 1}]})", "springs[0].i"},
      {"index fractional", std::string("{") + kTwo + R"(, "springs": [{"i": 0, "j": 1.5}]})", "springs[0].j"},
      {"i == j", std::string("{") + kTwo + R"(, "springs": [{"i": 1, "j": 1}]})", "springs[0]"},
      {"triangle repeated index", std::string("{") + kThree + R"(, "triangles": [{"i": 0, "j": 2, "k": 2}]})",
       "triangles[0]"},
      {"triangle zero rest area", std::string("{") + kThree + R"(, "triangles": [{"i": 0, "j": 1, "k": 2}]})",
       "triangles[0]"},
      {"stiffness zero", std::string("{") + kTwo + R"(, "springs": [{"i": 0, "j": 1, "stiffness": 0}]})",
       "springs[0].stiffness"},
      {"stiffness negative", R"({"chain": {"links": 2, "stiffness": -5}})", "chain.stiffness"},
      {"chain too long", R"({"chain": {"links": 100000000}})", "chain.links"},
      {"duplicate key", R"({"particles": [{"x": [0,0,0], "x": [1,0,0]}]})", "particles[0].x"},
      {"mass too small", R"({"particles": [{"x": [0,0,0], "mass": 1e-320}]})", "particles[0].mass: must be in"},
      {"mass too large", R"({"particles": [{"x": [0,0,0], "mass": 1e160}]})", "particles[0].mass: must be in"},
      {"velocity too large", R"({"particles": [{"x": [0,0,0], "v": [1e300,0,0]}]})", "particles[0].v[0]: must be in"},
      {"position too far", R"({"particles": [{"x": [0,0,0]}, {"x": [1e200,0,0]}], "springs": [{"i": 0, "j": 1}]})",
       "particles[1].x[0]: must be in"},
      {"dt too large", R"({"dt": 1e300, "particles": [{"x": [0,0,0]}]})", "dt: must be in [1e-9, 10] s"},
      {"steps past the range", R"({"steps": 1e12, "particles": [{"x": [0,0,0]}]})", "steps: must be an integer in"},
      {"sphere radius too large", R"({"particles": [{"x": [0,0,0]}],
          "colliders": [{"type": "sphere", "centre": [0,0,0], "radius": 1e308}]})", "colliders[0].radius: must be in"},
      {"cloth too wide", R"({"cloth": {"nx": 5000}})", "cloth.nx"},
      {"cloth cell area underflows", R"({"cloth": {"nx": 4, "width": 1e-200}})", "cloth.width"},
      {"cloth unknown pin", R"({"cloth": {"nx": 4, "pin": ["centre"]}})", "cloth.pin[0]"},
  };
  int index = 0;
  for (const Rule& rule : rules) {
    const cl::test::ScratchDir scratch("bad_input_" + std::to_string(index++));
    const fs::path dir = scratch.path();
    CAPTURE(rule.what, rule.text);
    const RunResult result = run_scene(rule.text, dir);
    CAPTURE(result.stderr_text);
    CHECK(result.exit_code == 2);
    CHECK_THAT(result.stderr_text, ContainsText((dir / "bad.json").string()));
    CHECK_THAT(result.stderr_text, ContainsText(rule.field));
    CHECK(std::count(result.stderr_text.begin(), result.stderr_text.end(), '\n') == 1);
    CHECK_FALSE(fs::exists(dir / "out"));
  }
}

TEST_CASE("bad command lines exit 2 with one line", "[common][bad-input]") {
  const cl::test::ScratchDir scratch("bad_cli");
  const fs::path dir = scratch.path();
  const std::string folder = "--scene '" + dir.string() + "'";
  for (const std::string& arguments : {std::string("--no-such-flag"), std::string("--scene no-such-scene"),
                                       std::string("--scene /no/such/file.json"), std::string("--scene"), folder}) {
    CAPTURE(arguments);
    const RunResult result = run_probe(arguments, dir);
    CAPTURE(result.stderr_text);
    CHECK(result.exit_code == 2);
    CHECK(std::count(result.stderr_text.begin(), result.stderr_text.end(), '\n') == 1);
    CHECK_THAT(result.stderr_text, StartsWith("lab01_single_spring"));
  }
  CHECK_THAT(run_probe(folder, dir).stderr_text, ContainsText("is a folder, not a scene file"));
}
