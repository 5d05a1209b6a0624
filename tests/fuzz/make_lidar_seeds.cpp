// Writes the lidar_packets seed corpus: 10 packets each of a synthetic VLP-16, RS-16 and dual-return VLP-16
// (tests/drivers/synthetic_lidar), spinning fast (3 packets per revolution) so that a small input holds
// several sweeps. Build and run (from the repository root) when the packet formats change:
//   cmake --build build --target fuzz_make_lidar_seeds && build/bin/fuzz_make_lidar_seeds tests/fuzz/corpus/lidar_packets
#include "synthetic_lidar.hpp"
#include <cstdio>
#include <string>
using namespace adit::drivers::testing;
static void put(std::string& out, const std::vector<std::uint8_t>& p, int dt_us) {
  out.push_back(static_cast<char>(p.size() & 0xFF)); out.push_back(static_cast<char>(p.size() >> 8));
  out.push_back(static_cast<char>(dt_us & 0xFF)); out.push_back(static_cast<char>(dt_us >> 8));
  out.append(reinterpret_cast<const char*>(p.data()), p.size());
}
int main(int, char** argv) {
  const char* names[] = {"vlp16", "rs16", "vlp16_dual"};
  for (int m = 0; m < 3; ++m) {
    SyntheticLidar lidar;
    lidar.model = m == 1 ? Model::kRs16 : Model::kVlp16;
    lidar.dual = m == 2;
    lidar.gap_centideg = 1000;  // 3 packets per revolution: a few sweeps in a small input
    if (m == 1) lidar.stamp0_us = kRs16TestEpochUs;
    std::string out(1, static_cast<char>(m == 1 ? 1 : 0));
    for (int k = 0; k < 10; ++k) put(out, lidar.packet(k), static_cast<int>(lidar.packetNs() / 1000));
    FILE* f = std::fopen((std::string(argv[1]) + "/" + names[m]).c_str(), "wb");
    std::fwrite(out.data(), 1, out.size(), f);
    std::fclose(f);
  }
}
