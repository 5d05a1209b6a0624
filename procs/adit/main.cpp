// adit: the command-line tool (import data sets, replay logs through the pipeline, launch and supervise the
// processes, open lcm-spy, evaluate trajectories). `adit <command> --help` documents each command.
#include "commands.hpp"

#include "core/config.hpp"
#include "runtime/allocator.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>

std::string executableDir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string(".") : exe.parent_path().string();
}

void drawProgress(double fraction) {
  const int width = 40;
  const int filled = static_cast<int>(fraction * width + 0.5);
  std::fprintf(stderr, "\r[%s%s] %3d%%", std::string(static_cast<std::size_t>(filled), '#').c_str(),
               std::string(static_cast<std::size_t>(width - filled), ' ').c_str(), static_cast<int>(fraction * 100 + 0.5));
  if (fraction >= 1.0) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

int main(int argc, char** argv) {
  adit::runtime::keepFreedMemoryForReuse();
  CLI::App app{"adit: real-time 3D mapping of underground roadways with a spinning lidar", "adit"};
  app.require_subcommand(1);
  spdlog::set_pattern("%H:%M:%S.%e %^%l%$ adit: %v");
  registerImportCommand(app);
  registerInfoCommand(app);
  registerConfigCommand(app);
  registerSimCommand(app);
  registerDemoCommand(app);
  registerBenchCommand(app);
  registerReplayCommand(app);
  registerLaunchCommand(app);
  registerSpyCommand(app);
  registerEvalCommand(app);
  registerCommandCommand(app);
  registerExportCommand(app);
  registerViewCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const adit::ConfigError& e) {  // a bad configuration: one line, status 2 (as the processes)
    spdlog::error("{}", e.what());
    return 2;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
