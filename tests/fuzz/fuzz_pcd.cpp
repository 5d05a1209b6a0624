// PCD files (ascii, binary, binary_compressed) through the reader adit import pcd uses: header checks,
// body decoding (LZF), field reading, rings by elevation and per-point times.
#include "fuzz_input.hpp"
#include "io/pcd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::fuzz::Input in(data, size);
  const std::string path = adit::fuzz::scratch().write("scan.pcd", in.rest());
  try {
    adit::io::PcdFolderConfig config;
    config.sensor = size % 2 ? "vlp16" : "unknown";  // beam table, or a uniform fan
    config.num_beams = 16;
    adit::io::readPcdScan(path, config, 0, 0);
  } catch (const adit::io::ReadError&) {
  }
  return 0;
}
