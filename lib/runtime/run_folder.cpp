#include "runtime/run_folder.hpp"

#include <cstdlib>
#include <filesystem>

namespace adit::runtime {
namespace fs = std::filesystem;

std::string RunFolder::file(const std::string& name) const { return (fs::path(dir) / name).string(); }

RunFolder liveRunFolder(const std::string& flag_dir) {
  RunFolder folder;
  folder.live = true;
  const char* env_dir = std::getenv("ADIT_RUN_DIR");
  if (!flag_dir.empty()) {
    folder.dir = flag_dir;
    folder.given = true;
  } else if (env_dir && *env_dir) {
    folder.dir = env_dir;
    folder.given = true;
  }
  std::error_code ec;
  fs::create_directories(folder.dir, ec);  // a failure shows up, with the path, when something is written
  const char* env_id = std::getenv("ADIT_RUN_ID");
  if (env_id && *env_id) {
    folder.run_id = env_id;
  } else {
    const fs::path absolute = fs::weakly_canonical(fs::absolute(folder.dir, ec), ec);
    folder.run_id = absolute.filename().string();
    if (folder.run_id.empty()) folder.run_id = absolute.parent_path().filename().string();
  }
  if (const char* restarts = std::getenv("ADIT_RESTART_COUNT")) folder.restart_count = std::atoi(restarts);
  return folder;
}

std::string plainFileNameProblem(const std::string& name) {
  if (name.empty()) return "empty file name";
  if (name.size() > kMaxCommandFileName)
    return "file name longer than " + std::to_string(kMaxCommandFileName) + " characters";
  if (name.front() == '.' || name.front() == '-') return "file name starts with '" + std::string(1, name.front()) + "'";
  for (const char c : name) {
    const bool allowed = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                         c == '_' || c == '-';
    if (!allowed) return c == '/' || c == '\\' ? "path separators are not allowed: a plain file name only"
                                               : "character outside [A-Za-z0-9._-]";
  }
  return "";
}

}  // namespace adit::runtime
