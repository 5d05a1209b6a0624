// adit-imu-bridge: publishes a recorded IMU file (`t gx gy gz ax ay az [mx my mz]` per line) on IMU at the
// recorded rate (or --rate times it), or writes it straight into an LCM log with -o.
#include "runtime/source.hpp"
#include "sources/file_sources.hpp"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

int main(int argc, char** argv) {
  CLI::App app{"Publish recorded IMU samples on LCM (or write them to a log)", "adit-imu-bridge"};
  std::string path, channel = "IMU";
  adit::runtime::SourceRunOptions run;
  run.process = "imu-bridge";
  app.add_option("--path", path, "IMU text file")->required()->check(CLI::ExistingFile);
  app.add_option("--channel", channel, "Channel of the samples");
  app.add_option("--rate", run.rate, "Playback speed as a multiple of the recorded rate (0 = as fast as possible)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("-o,--output", run.output_log, "Write an LCM log instead of publishing live");
  app.add_option("--lcm-url", run.lcm_url, "LCM provider (default: $LCM_DEFAULT_URL or udpm)");
  app.add_flag("--keep-going", run.keep_going, "With -o: skip (and count) bad lines instead of writing no log");
  CLI11_PARSE(app, argc, argv);
  run.input = path;
  spdlog::set_pattern("%H:%M:%S.%e %^%l%$ adit-imu-bridge: %v");
  try {
    auto src = adit::sources::makeImuCsvSource(path, channel);
    return adit::runtime::runSource(*src, run);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
