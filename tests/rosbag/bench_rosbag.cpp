// Bag import throughput: MB of bag file per second through the reader alone and through the whole import
// source (decompression, PointCloud2 decoding with the PCD field conversion, sweep encoding), for each
// chunk compression. The bag: 20 VLP-16-size sweeps (16 x 1800 points, Velodyne layout, 634 kB each) and
// 100 Hz IMU, in 768 kB-ish chunks (two sweeps each), written by the tests' bag writer.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <map>

#include <unistd.h>

#include "bag_writer.hpp"
#include "clouds.hpp"
#include "io/rosbag.hpp"
#include "sources/rosbag_source.hpp"

namespace {

using namespace adit::test;

// The bags, written once per run and removed at exit.
struct BagFiles {
  std::map<std::string, std::string> paths;
  std::int64_t message_bytes = 0;  // serialised messages in one bag (the same for every compression)
  ~BagFiles() {
    for (const auto& [c, p] : paths) std::filesystem::remove(p);
  }
};
BagFiles files;

std::string bagPath(const std::string& compression) {
  if (files.paths.count(compression)) return files.paths[compression];
  files.message_bytes = 0;
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("adit_bench_" + std::to_string(::getpid()) + "_" + compression + ".bag")).string();
  files.paths[compression] = path;
  BagWriter w(compression);
  w.addConnection(0, "/velodyne_points", "sensor_msgs/PointCloud2");
  w.addConnection(1, "/imu", "sensor_msgs/Imu");
  for (int k = 0; k < 20; ++k) {
    const auto nsec = static_cast<std::uint32_t>(k) * 100000000u;
    const Bytes cloud = velodyneCloud(1600000000u + k / 10, nsec % 1000000000u, 1800, k).message;
    w.addMessage(0, 1600000000LL * 1000000000 + nsec, cloud);
    files.message_bytes += static_cast<std::int64_t>(cloud.size());
    for (int i = 0; i < 10; ++i) {
      const Bytes imu = imuMessage(1600000000u + k / 10, (nsec + i * 10000000u) % 1000000000u, adit::ImuSample{});
      w.addMessage(1, 1600000000LL * 1000000000 + nsec + i * 10000000, imu);
      files.message_bytes += static_cast<std::int64_t>(imu.size());
    }
    if (k % 2) w.endChunk();
  }
  std::ofstream(path, std::ios::binary) << w.finish();
  return path;
}

// bytes_per_second: bag file bytes; message_bytes: the serialised messages it holds (uncompressed), per second.
void report(benchmark::State& state, const std::string& path) {
  const auto n = static_cast<double>(state.iterations());
  state.SetBytesProcessed(static_cast<std::int64_t>(n * static_cast<double>(std::filesystem::file_size(path))));
  state.counters["file_MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  state.counters["message_bytes"] = benchmark::Counter(n * static_cast<double>(files.message_bytes), benchmark::Counter::kIsRate);
}

void BM_BagReader(benchmark::State& state, const std::string& compression) {
  const std::string path = bagPath(compression);
  for (auto _ : state) {
    adit::io::BagReader reader(path);
    adit::io::BagMessage m;
    while (reader.next(m)) benchmark::DoNotOptimize(m.data.data());
  }
  report(state, path);
}

void BM_BagImport(benchmark::State& state, const std::string& compression) {
  const std::string path = bagPath(compression);
  adit::sources::RosbagSourceConfig config;
  config.lidar_topic = "/velodyne_points";
  config.imu_topic = "/imu";
  for (auto _ : state) {
    auto source = adit::sources::makeRosbagSource(path, config);
    adit::runtime::OutgoingMessage m;
    while (source->next(m)) benchmark::DoNotOptimize(m.data.data());
  }
  report(state, path);
}

BENCHMARK_CAPTURE(BM_BagReader, none, std::string("none"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BagReader, bz2, std::string("bz2"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BagReader, lz4, std::string("lz4"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BagImport, none, std::string("none"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BagImport, bz2, std::string("bz2"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BagImport, lz4, std::string("lz4"))->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
