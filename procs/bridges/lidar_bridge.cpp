// adit-lidar-bridge: publishes recorded sweeps (KITTI layout or a PCD folder) on LIDAR_POINTS at the
// recorded rate (or --rate times it), or writes them straight into an LCM log with -o.
#include "runtime/process.hpp"
#include "runtime/source.hpp"
#include "sources/source_options.hpp"

#include <spdlog/spdlog.h>

int main(int argc, char** argv) {
  CLI::App app{"Publish recorded lidar sweeps on LCM (or write them to a log)", "adit-lidar-bridge"};
  adit::sources::LidarSourceArgs source;
  adit::runtime::SourceRunOptions run;
  run.process = "lidar-bridge";
  addLidarSourceOptions(app, source, false);
  app.add_option("--rate", run.rate, "Playback speed as a multiple of the recorded rate (0 = as fast as possible)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("-o,--output", run.output_log, "Write an LCM log instead of publishing live");
  app.add_option("--lcm-url", run.lcm_url, "LCM provider (default: $LCM_DEFAULT_URL or udpm)");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_pattern("%H:%M:%S.%e %^%l%$ adit-lidar-bridge: %v");
  try {
    auto src = adit::sources::makeLidarSource(source);
    return adit::runtime::runSource(*src, run);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
