// libFuzzer target for the scene loader (docs/DESIGN.md §3): any text either
// parses into a scene that keeps the loader's promises
// (tests/support/scene_promises.h) or is rejected with cl::InputError. Any
// other exception, a crash, a sanitizer report or a broken promise is a bug;
// libFuzzer keeps the input and ./course fuzz copies it into
// tests/common/scene_regressions/, where the unit tests replay it.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "common/scene.h"
#include "tests/support/scene_promises.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const std::string broken = cl::test::broken_promise(cl::parse_scene(text, "fuzz.json"));
    if (!broken.empty()) {
      std::fprintf(stderr, "accepted a scene that breaks a promise: %s\n", broken.c_str());
      std::abort();  // libFuzzer reports the input as a crash
    }
  } catch (const cl::InputError&) {
    // Rejected with one line naming the field: the contract.
  }
  return 0;
}
