// Reader throughput on real data: one KITTI HDL-64E scan (~124k points) read with rings and times,
// ring assignment alone, and the same cloud written and read back as binary PCD.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "io/kitti.hpp"
#include "io/pcd.hpp"
#include "io/rings.hpp"

namespace {

const std::string kSequence = std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini/sequences/00";
const std::string kScan = kSequence + "/velodyne/000000.bin";

void BM_KittiScanWithRingsAndTimes(benchmark::State& state) {
  const adit::io::KittiSequence seq(kSequence);
  for (auto _ : state) benchmark::DoNotOptimize(seq.scan(0).points.data());
}
BENCHMARK(BM_KittiScanWithRingsAndTimes)->Unit(benchmark::kMillisecond);

void BM_RingsByScanOrder(benchmark::State& state) {
  auto points = adit::io::readKittiBin(kScan);
  for (auto _ : state) benchmark::DoNotOptimize(adit::io::assignRingsByScanOrder(points, 64));
}
BENCHMARK(BM_RingsByScanOrder)->Unit(benchmark::kMillisecond);

void BM_RingsByElevation(benchmark::State& state) {
  auto points = adit::io::readKittiBin(kScan);
  const auto table = adit::io::hdl64Elevations();
  for (auto _ : state) benchmark::DoNotOptimize(adit::io::assignRingsByElevation(points, table, 0.01).num_beams);
}
BENCHMARK(BM_RingsByElevation)->Unit(benchmark::kMillisecond);

void BM_PcdWriteAndRead(benchmark::State& state) {
  const auto points = adit::io::readKittiBin(kScan);
  const std::string path = (std::filesystem::temp_directory_path() / "adit_bench_io.pcd").string();
  for (auto _ : state) {
    adit::io::writePcd(path, points, {true, true});
    benchmark::DoNotOptimize(adit::io::readPcdScan(path, adit::io::PcdFolderConfig{}, 0, 0).points.data());
  }
  std::filesystem::remove(path);
}
BENCHMARK(BM_PcdWriteAndRead)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
