// Replays every file of tests/fuzz/corpus/<harness>/ and tests/fuzz/regressions/<harness>/ through the
// harnesses, compiled plainly (no fuzzer, no sanitizer): inputs that once crashed a reader must stay
// harmless in the build CI tests. A crash fails the test; so does a harness without a seed corpus.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_harnesses.hpp"  // generated: kHarnesses {name, entry}

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> filesIn(const fs::path& dir) {
  std::vector<fs::path> paths;
  if (!fs::is_directory(dir)) return paths;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename().string()[0] != '.') paths.push_back(e.path());
  std::sort(paths.begin(), paths.end());
  return paths;
}

TEST(FuzzRegressions, EverySeedAndRegressionInputIsHandled) {
  const fs::path root = ADIT_FUZZ_DIR;
  for (const auto& [name, entry] : kHarnesses) {
    std::size_t seeds = 0, regressions = 0;
    for (const char* kind : {"corpus", "regressions"}) {
      for (const fs::path& p : filesIn(root / kind / name)) {
        SCOPED_TRACE(p.string());
        std::ifstream f(p, std::ios::binary);
        const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
        EXPECT_EQ(entry(bytes.data(), bytes.size()), 0);
        ++(std::string(kind) == "corpus" ? seeds : regressions);
      }
    }
    std::printf("%-16s %3zu seeds, %3zu regression inputs replayed\n", name, seeds, regressions);
    EXPECT_GT(seeds, 0u) << name << " has no seed corpus";
  }
}

}  // namespace
