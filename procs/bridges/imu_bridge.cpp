// adit-imu-bridge: publishes IMU samples on IMU, from a recorded text file (`t gx gy gz ax ay az [mx my mz]`
// per line) at the recorded rate (or --rate times it), or from a serial IMU (the WHEELTEC N100's binary
// protocol or the same text a line) as they arrive; -o writes an LCM log instead of publishing.
#include "drivers/serial_imu_source.hpp"
#include "runtime/source.hpp"
#include "sources/file_sources.hpp"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

int main(int argc, char** argv) {
  CLI::App app{"Publish IMU samples on LCM (or write them to a log), from a file or a serial IMU", "adit-imu-bridge"};
  std::string source = "file", path, channel = "IMU";
  adit::drivers::SerialImuConfig serial;
  adit::runtime::SourceRunOptions run;
  run.process = "imu-bridge";
  app.add_option("--source", source, "file (a recorded text file) or serial (a device)")
      ->check(CLI::IsMember({"file", "serial"}))->capture_default_str();
  app.add_option("--path", path, "IMU text file (--source file)")->check(CLI::ExistingFile);
  app.add_option("--device", serial.device, "Serial device (--source serial)")->capture_default_str();
  app.add_option("--baud", serial.baud, "Baud rate")->capture_default_str();
  app.add_option("--protocol", serial.protocol, "n100 (WHEELTEC N100 / FDILink binary frames) or text")
      ->check(CLI::IsMember({"n100", "text"}))->capture_default_str();
  app.add_option("--clock", serial.clock,
                 "sync: the device's stamps mapped onto the host clock (offset and drift filtered); host: receive time")
      ->check(CLI::IsMember({"sync", "host"}))->capture_default_str();
  app.add_option("--transport-delay", serial.transport_delay_s,
                 "Fixed delay from sampling to receive, s (default: one frame's bytes at the baud rate)");
  app.add_option("--channel", channel, "Channel of the samples");
  app.add_option("--rate", run.rate, "File playback speed as a multiple of the recorded rate (0 = as fast as possible)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("-o,--output", run.output_log, "Write an LCM log instead of publishing live");
  app.add_option("--lcm-url", run.lcm_url, "LCM provider (default: $LCM_DEFAULT_URL or udpm)");
  app.add_flag("--keep-going", run.keep_going, "With -o: skip (and count) bad lines instead of writing no log");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_pattern("%H:%M:%S.%e %^%l%$ adit-imu-bridge: %v");
  try {
    std::unique_ptr<adit::runtime::MessageSource> src;
    if (source == "serial") {
      serial.channel = channel;
      run.input = serial.device;
      run.rate = 0;  // a device paces itself
      src = adit::drivers::makeSerialImuSource(serial);
    } else {
      if (path.empty()) throw std::invalid_argument("--source file needs --path");
      run.input = path;
      src = adit::sources::makeImuCsvSource(path, channel);
    }
    return adit::runtime::runSource(*src, run);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
