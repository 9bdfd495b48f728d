#pragma once
// Output files are written whole or not at all: a run that fails part-way
// leaves no half-written file behind.
#include <string>

namespace cl {

// Writes `content` to `path` through a temporary file and a rename, creating
// parent directories. Throws InputError naming the path when it cannot.
void write_file_atomic(const std::string& path, const std::string& content);

// Creates `dir` (and parents) if needed. Throws InputError when it cannot.
// Under --check it creates nothing and throws CheckStop instead: a checked
// run stops before its first file, wherever that is.
void ensure_directory(const std::string& dir);

// --check (docs/DESIGN.md §3): the run parses its flags, loads its scenes and
// refuses bad input exactly as it would, and stops where it would start
// (cl::start_run, common/cli.h) by throwing CheckStop, which cl::run_main
// reports in one line with exit 0. Nothing is written and nothing is solved.
void set_check_mode(bool on);
bool check_mode();
struct CheckStop {
  std::string detail;  // what the run would do beyond its scenes: ", --method pd, writes out/x/"
};

// Throws CheckStop under --check; a no-op otherwise. The places where a run
// starts its work call it (the frame loop, the live loop, start_run), so that
// a path that reaches its work without start_run still stops before it.
void stop_if_checking();

// `dir`/`file`, or just `file` when dir is empty.
std::string join_path(const std::string& dir, const std::string& file);

// 17 significant digits: enough to read back the same double.
std::string format_double(double value);

}  // namespace cl
