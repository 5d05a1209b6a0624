// Writes the lidar_packets seed corpus: 10 packets each of a synthetic VLP-16, RS-16 and dual-return VLP-16
// (tests/drivers/synthetic_lidar), spinning fast (3 packets per revolution) so that a small input holds
// several sweeps; and the RS-16's again after a DIFOP packet (dual return, nominal angles), with a second
// DIFOP (single return) among them. Build and run (from the repository root) when the packet formats change:
//   cmake --build build --target fuzz_make_lidar_seeds && build/bin/fuzz_make_lidar_seeds tests/fuzz/corpus/lidar_packets
#include "synthetic_lidar.hpp"
#include <cstdio>
#include <string>
using namespace adit::drivers::testing;
// One packet of the harness's input; device_info: a DIFOP packet (the size's top bit set).
static void put(std::string& out, const std::vector<std::uint8_t>& p, int dt_us, bool device_info = false) {
  const std::size_t field = p.size() | (device_info ? 0x8000u : 0u);
  out.push_back(static_cast<char>(field & 0xFF)); out.push_back(static_cast<char>(field >> 8));
  out.push_back(static_cast<char>(dt_us & 0xFF)); out.push_back(static_cast<char>(dt_us >> 8));
  out.append(reinterpret_cast<const char*>(p.data()), p.size());
}
int main(int, char** argv) {
  const char* names[] = {"vlp16", "rs16", "vlp16_dual", "rs16_difop"};
  for (int m = 0; m < 4; ++m) {
    SyntheticLidar lidar;
    lidar.model = m == 1 || m == 3 ? Model::kRs16 : Model::kVlp16;
    lidar.dual = m == 2;
    lidar.gap_centideg = 1000;  // 3 packets per revolution: a few sweeps in a small input
    if (lidar.model == Model::kRs16) lidar.stamp0_us = kRs16TestEpochUs;
    std::string out(1, static_cast<char>(lidar.model == Model::kRs16 ? 1 : 0));
    if (m == 3) put(out, rs16DifopPacket(true, nominalRs16Elevations()), 0, true);
    for (int k = 0; k < 10; ++k) {
      if (m == 3 && k == 5) put(out, rs16DifopPacket(false, nominalRs16Elevations()), 0, true);
      put(out, lidar.packet(k), static_cast<int>(lidar.packetNs() / 1000));
    }
    FILE* f = std::fopen((std::string(argv[1]) + "/" + names[m]).c_str(), "wb");
    std::fwrite(out.data(), 1, out.size(), f);
    std::fclose(f);
  }
}
