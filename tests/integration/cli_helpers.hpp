// Running adit's programs from tests and reading what they wrote.
#pragma once

#include "runtime/lcm_log.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace adit::test {

inline std::string bin(const std::string& program) { return std::string(ADIT_BIN_DIR) + "/" + program; }
inline std::string kittiSequence(const std::string& nn) {
  return std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini/sequences/" + nn;
}

// A fresh folder per test under the system temp dir.
inline std::filesystem::path freshDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("adit_it_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Runs a shell command line; returns its exit code (output goes to <log>).
inline int run(const std::string& command, const std::filesystem::path& log) {
  const int status = std::system((command + " > '" + log.string() + "' 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), {}};
}

// Payloads per channel, in log order.
inline std::map<std::string, std::vector<std::vector<std::uint8_t>>> payloads(const std::string& log) {
  std::map<std::string, std::vector<std::vector<std::uint8_t>>> out;
  runtime::LogReader reader(log);
  runtime::LogEvent e;
  while (reader.next(e)) out[e.channel].push_back(e.data);
  return out;
}

}  // namespace adit::test
