// A KITTI sequence folder: times.txt and one velodyne .bin, through KittiSequence (times parsing, point
// decoding, rings by scan order or elevation, per-point times).
// Input: uint16 length of times.txt, its text, then the .bin bytes.
#include "fuzz_input.hpp"
#include "io/kitti.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::fuzz::Input in(data, size);
  const auto& dir = adit::fuzz::scratch();
  dir.write("seq/times.txt", in.bytes(in.u16()));
  dir.write("seq/velodyne/000000.bin", in.rest());
  try {
    const adit::io::KittiSequence sequence(dir.path() + "/seq");
    for (std::size_t i = 0; i < sequence.size(); ++i) sequence.scan(i);
  } catch (const adit::io::ReadError&) {
  }
  return 0;
}
