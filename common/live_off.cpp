// The live mode in a build without it (CL_LIVE=OFF in CMakeLists.txt, the
// MinGW lane's until the live server leaves POSIX sockets for Boost.Asio):
// --live is still accepted by every lab's command line, and says so here.
#include "common/live.h"

#include "common/scene.h"

namespace cl {

namespace {
const char* const kNoLive = "--live: this build has no live mode (configured with CL_LIVE=OFF)";
}  // namespace

std::string live_page() { throw InputError(kNoLive); }

int run_live(Scene&, const LiveOptions&, const LiveRun&, const std::string&) { throw InputError(kNoLive); }

}  // namespace cl
