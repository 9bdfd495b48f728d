// Inputs that once broke the scene loader, or are likely to, replayed on every
// test run: each must be rejected with cl::InputError or parse into a scene
// that keeps the loader's promises. `./course fuzz` adds a crashing input here
// by itself (tests/common/scene_regressions/); fix the loader, then commit it.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "tests/support/catch.h"

#include "common/scene.h"
#include "tests/support/scene_promises.h"

namespace {
namespace fs = std::filesystem;

std::vector<fs::path> regression_inputs() {
  std::vector<fs::path> inputs;
  for (const auto& entry : fs::directory_iterator(fs::path(CL_SOURCE_DIR) / "tests/common/scene_regressions")) {
    if (entry.is_regular_file() && entry.path().filename() != "README.md") inputs.push_back(entry.path());
  }
  std::sort(inputs.begin(), inputs.end());
  return inputs;
}
}  // namespace

TEST_CASE("every saved fuzz input is rejected cleanly or keeps the scene promises", "[common][scene][fuzz]") {
  const std::vector<fs::path> inputs = regression_inputs();
  REQUIRE(!inputs.empty());  // the folder ships with seeds; an empty one means it went missing
  for (const fs::path& path : inputs) {
    std::ifstream file(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    CAPTURE(path.filename().string(), text.size());
    std::string outcome;
    try {
      const std::string broken = cl::test::broken_promise(cl::parse_scene(text, path.filename().string()));
      outcome = broken.empty() ? "accepted" : "accepted, but " + broken;
    } catch (const cl::InputError& error) {
      outcome = "rejected";
      CAPTURE(error.what());
      CHECK(std::string(error.what()).find(path.filename().string()) == 0);  // names the file first
    } catch (const std::exception& error) {
      outcome = std::string("threw something other than InputError: ") + error.what();
    }
    CAPTURE(outcome);
    CHECK((outcome == "accepted" || outcome == "rejected"));
  }
}
