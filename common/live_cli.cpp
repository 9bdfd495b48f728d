// `--live [PORT]`: the one flag of the live mode. It takes an optional value,
// which cl::CommandLine's option types do not offer, so this file includes
// CLI11 as common/cli.cpp does. It is cl_live's (CMakeLists.txt), built with
// or without Boost: every live lab's main.cpp registers the flag.
#include <CLI/CLI.hpp>

#include "common/live.h"

namespace cl {

void add_live_option(CommandLine& line, LiveOptions& live) {
  line.app()
      .add_option_function<std::string>(
          "--live",
          [&live](const std::string& port) {
            live.on = true;
            live.port = port.empty() ? 0 : std::stoi(port);
          },
          "step the scene live beside a page in the browser (./course live): serves it on 127.0.0.1:PORT "
          "(default: a free port) and prints its URL; Ctrl-C or the page's stop ends it")
      ->expected(0, 1)
      ->check(CLI::Validator(
          [](std::string& port) { return port.empty() ? std::string() : integer_in(1, 65535)(port); }, "PORT"));
}

}  // namespace cl
