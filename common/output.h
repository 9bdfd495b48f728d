#pragma once
// Output files are written whole or not at all: a run that fails part-way
// leaves no half-written file behind.
#include <string>

namespace cl {

// Writes `content` to `path` through a temporary file and a rename, creating
// parent directories. Throws InputError naming the path when it cannot.
void write_file_atomic(const std::string& path, const std::string& content);

// Creates `dir` (and parents) if needed. Throws InputError when it cannot.
void ensure_directory(const std::string& dir);

// `dir`/`file`, or just `file` when dir is empty.
std::string join_path(const std::string& dir, const std::string& file);

// 17 significant digits: enough to read back the same double.
std::string format_double(double value);

}  // namespace cl
