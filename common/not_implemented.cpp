#include "common/not_implemented.h"

#include "common/source_dir.h"

namespace cl {

namespace {
// Print paths relative to the course so messages read the same on every machine.
std::string course_relative(const std::string& path) {
  const std::string root = std::string(source_dir()) + "/";
  if (path.compare(0, root.size(), root) == 0) return path.substr(root.size());
  return path;
}
}  // namespace

NotImplemented::NotImplemented(std::string function, std::string file)
    : std::logic_error(function + " is not implemented yet (" + course_relative(file) + ")"),
      function_(std::move(function)),
      file_(course_relative(file)) {}

void not_implemented(const char* function, const char* file) {
  throw NotImplemented(function, file);
}

}  // namespace cl
