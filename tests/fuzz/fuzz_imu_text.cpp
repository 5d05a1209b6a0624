// IMU text files (adit-imu-bridge) through the line parser and the file reader.
#include "fuzz_input.hpp"
#include "io/imu_csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::fuzz::Input in(data, size);
  const std::string path = adit::fuzz::scratch().write("imu.txt", in.rest());
  try {
    adit::io::readImuCsv(path).badLineSummary();
  } catch (const adit::io::ReadError&) {
  }
  return 0;
}
