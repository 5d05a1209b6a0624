// adit-lidar-bridge: publishes sweeps on LIDAR_POINTS: live from a VLP-16 / RS-16 (UDP packets), or
// recorded (KITTI layout, PCD folder, pcap/pcapng capture of the sensor's packets) at the recorded rate (or
// --rate times it; 0 = as fast as possible); -o writes an LCM log instead.
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
    if (adit::sources::isLiveSource(source)) run.rate = 0;  // a sensor paces itself
    return adit::runtime::runSource(*src, run);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
