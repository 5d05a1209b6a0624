// Writes the seed corpus of the map_bundle harness: small bundles (three keyframes of a box-section roadway)
// with the relocaliser's own Scan Context grid and with a smaller one, packed as the harness reads them.
// Run from the repository root: build/bin/fuzz_make_bundle_seeds tests/fuzz/corpus/map_bundle
#include "map/map_bundle.hpp"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace {
namespace fs = std::filesystem;

adit::MapBundle smallBundle(const adit::ScanContextConfig& sc) {
  adit::MapBundle b;
  for (int k = 0; k < 3; ++k) {
    std::vector<Eigen::Vector3f> points;
    for (int i = 0; i < 60; ++i) {
      const float x = -6.0f + 0.2f * static_cast<float>(i), z = static_cast<float>(i % 5) * 0.4f - 1.0f;
      points.emplace_back(x, 2.2f, z);
      points.emplace_back(x, -2.2f, z + 0.1f * static_cast<float>(k));
    }
    adit::BundleKeyframe kf;
    kf.utime = 1700000000000000 + k * 1000000;
    kf.pose.translation() = Eigen::Vector3d(k, 0.0, 0.0);
    kf.cloud = adit::CompactCloud::encode(points, 0.01f);
    kf.context = adit::ScanContext::build(points, sc);
    b.graph.addNode(kf.pose);
    if (k > 0) b.graph.addOdometryEdge(k - 1, k, b.keyframes.back().pose.inverse() * kf.pose, adit::Matrix6d::Identity());
    b.keyframes.push_back(std::move(kf));
    b.map.insert(b.map.end(), points.begin(), points.end());
  }
  b.config = {{"loop.scan_context.rings", std::to_string(sc.rings)}, {"mapping.voxel", "0.1"}};
  b.summary.created = "2023-11-14T22:13:25Z";
  b.summary.keyframes = 3;
  b.summary.extent_max = Eigen::Vector3d(2, 0, 0);
  b.summary.roadway_length_m = 2.0;
  b.summary.map_voxel = 0.1;
  b.summary.sensor = adit::bundleSensorKeys(b.config);
  return b;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void putField(std::string& out, const std::string& bytes) {
  out += static_cast<char>(bytes.size() & 0xFF);
  out += static_cast<char>((bytes.size() >> 8) & 0xFF);
  out += bytes;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: fuzz_make_bundle_seeds <corpus dir>\n";
    return 2;
  }
  const fs::path tmp = fs::temp_directory_path() / "adit_bundle_seeds";
  adit::ScanContextConfig small;
  small.rings = 5;
  small.sectors = 12;
  const std::pair<const char*, adit::ScanContextConfig> kinds[] = {{"default_grid", {}}, {"small_grid", small}};
  for (const auto& [name, sc] : kinds) {
    fs::remove_all(tmp);
    adit::writeMapBundle(smallBundle(sc), tmp.string());
    std::string manifest = slurp(tmp / "manifest.yaml");
    std::string seed;
    for (const bool fixup : {false, true}) {
      // With the fix-up bit the harness writes the files section itself: leave the written one out.
      const std::string m = fixup ? manifest.substr(0, manifest.find("files:")) : manifest;
      seed.clear();
      putField(seed, m);
      for (const char* file : {"keyframes.bin", "pose_graph.g2o", "config.yaml"}) putField(seed, slurp(tmp / file));
      seed += static_cast<char>(fixup ? 1 : 0);
      std::ofstream(fs::path(argv[1]) / (std::string(name) + (fixup ? "_fixup" : "_as_written")), std::ios::binary) << seed;
    }
  }
  fs::remove_all(tmp);
  return 0;
}
