// The live mode of a build without Boost (CMakeLists.txt: Boost.Beast carries
// the live server, common/live_server.h): the labs build and run, and --live
// is refused in one line that says what to install.
#include "common/live.h"
#include "common/output.h"

namespace cl {

int run_live(Scene&, const LiveOptions&, const LiveRun&, const std::string&) {
  stop_if_checking();
  throw InputError(
      "--live: this build has no live mode: it needs Boost 1.70 or later (Debian/Ubuntu: apt install libboost-dev; "
      "macOS: brew install boost; vcpkg: boost-beast), then configure again");
}

}  // namespace cl
