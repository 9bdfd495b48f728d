#include "common/output.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/scene.h"

namespace cl {

namespace fs = std::filesystem;

namespace {
bool checking = false;
}  // namespace

void set_check_mode(bool on) { checking = on; }
bool check_mode() { return checking; }

void stop_if_checking() {
  if (checking) throw CheckStop{};
}

void ensure_directory(const std::string& dir) {
  stop_if_checking();
  if (dir.empty()) return;
  std::error_code error;
  fs::create_directories(dir, error);
  if (error || !fs::is_directory(dir)) {
    throw InputError(dir + ": cannot create output directory (" + error.message() + ")");
  }
}

void write_file_atomic(const std::string& path, const std::string& content) {
  stop_if_checking();
  const fs::path target(path);
  if (target.has_parent_path()) ensure_directory(target.parent_path().string());
  const std::string temporary = path + ".part";
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file) throw InputError(path + ": cannot write output file");
    file << content;
    file.close();
    if (!file) {
      std::remove(temporary.c_str());
      throw InputError(path + ": cannot write output file");
    }
  }
  std::error_code error;
  fs::rename(temporary, target, error);
  if (error) {
    std::remove(temporary.c_str());
    throw InputError(path + ": cannot write output file (" + error.message() + ")");
  }
}

std::string join_path(const std::string& dir, const std::string& file) {
  return dir.empty() ? file : (fs::path(dir) / file).string();
}

std::string format_double(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

}  // namespace cl
