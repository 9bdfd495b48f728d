#pragma once
// A folder for a test's files: under the system's temporary folder, never the
// working directory (a test run leaves the build tree as it found it), named
// by the test and the process so that ctest's parallel cases and the sanitizer
// build's run beside the main one never share one, and removed with its files
// when the test is done.
//
//   const cl::test::ScratchDir scratch("trajectory");
//   cl::TrajectoryWriter writer(scratch.file("round_trip"), ...);
#include <filesystem>
#include <string>
#include <system_error>

#ifdef _WIN32
#include <process.h>  // _getpid
#else
#include <unistd.h>  // getpid
#endif

namespace cl::test {

inline long process_id() {
#ifdef _WIN32
  return static_cast<long>(::_getpid());
#else
  return static_cast<long>(::getpid());
#endif
}

class ScratchDir {
 public:
  explicit ScratchDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() / ("cl_test_" + name + "_" + std::to_string(process_id()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;  // a destructor must not throw; a leftover folder in /tmp is harmless
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  std::string path() const { return path_.string(); }
  // The path of `name` inside the folder (not created).
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace cl::test
