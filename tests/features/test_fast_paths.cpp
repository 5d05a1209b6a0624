// The feature stage's fast paths against plain reference implementations: the streaming voxel grid against
// a std::map of voxels, the ring ordering against std::stable_sort. Equality is bitwise: replay must give
// the same bytes as before the speed-ups.
#include "features/preprocess.hpp"
#include "features/voxel_centroids.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <tuple>

namespace adit {
namespace {

bool sameBits(const LidarPoint& a, const LidarPoint& b) {
  return std::memcmp(a.p.data(), b.p.data(), sizeof(float) * 3) == 0 && a.ring == b.ring &&
         std::memcmp(&a.dt, &b.dt, sizeof a.dt) == 0 && std::memcmp(&a.intensity, &b.intensity, sizeof a.intensity) == 0;
}

// Voxel downsampling written the obvious way: centroid (sum in input order / count) per voxel, in order of
// first occurrence; non-finite or absurd coordinates skipped.
std::vector<LidarPoint> referenceDownsample(const std::vector<LidarPoint>& pts, float leaf) {
  std::map<std::tuple<long long, long long, long long>, std::size_t> slot;
  std::vector<LidarPoint> out;
  std::vector<int> count;
  for (const LidarPoint& p : pts) {
    const Eigen::Array3f q = (p.p.array() * (1.0f / leaf)).floor();
    if (!q.allFinite() || (q.abs() > 1e15f).any()) continue;
    // The grid packs 21 bits an axis: coordinates equal modulo 2^21 voxels share a voxel there too.
    const auto wrap = [](float v) { return static_cast<long long>(static_cast<std::int64_t>(v) & 0x1FFFFF); };
    const auto key = std::make_tuple(wrap(q.x()), wrap(q.y()), wrap(q.z()));
    const auto it = slot.find(key);
    if (it == slot.end()) {
      slot.emplace(key, out.size());
      out.push_back(p);
      count.push_back(1);
    } else {
      out[it->second].p += p.p;
      ++count[it->second];
    }
  }
  for (std::size_t k = 0; k < out.size(); ++k) out[k].p = out[k].p / static_cast<float>(count[k]);
  return out;
}

TEST(FastPaths, VoxelGridEqualsReferenceBitForBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-40.0f, 40.0f);
  std::vector<LidarPoint> pts;
  for (int k = 0; k < 60000; ++k) {  // runs of nearby points (as along a ring) and jumps: the table grows
    LidarPoint p;
    p.p = k % 7 == 0 || pts.empty() ? Eigen::Vector3f(u(rng), u(rng), u(rng))
                                    : Eigen::Vector3f(pts.back().p + Eigen::Vector3f(0.013f, -0.004f, 0.002f));
    p.ring = static_cast<std::uint16_t>(k % 16);
    p.dt = -1e-6f * static_cast<float>(k);
    p.intensity = static_cast<float>(k % 255);
    pts.push_back(p);
  }
  pts[100].p.x() = std::numeric_limits<float>::quiet_NaN();
  pts[200].p.y() = std::numeric_limits<float>::infinity();
  pts[300].p.z() = 3e16f;  // beyond any voxel index
  pts[400].p = {-0.0f, 0.0f, -1e-30f};
  for (const float leaf : {0.1f, 0.2f, 1.0f}) {
    const std::vector<LidarPoint> fast = features::voxelDownsample(pts, leaf), ref = referenceDownsample(pts, leaf);
    ASSERT_EQ(fast.size(), ref.size()) << leaf;
    for (std::size_t k = 0; k < ref.size(); ++k) ASSERT_TRUE(sameBits(fast[k], ref[k])) << leaf << " voxel " << k;
  }
  EXPECT_TRUE(features::voxelDownsample({}, 0.2f).empty());
}

TEST(FastPaths, RingsAreOrderedLikeAStableSortByTime) {
  // 4 rings of 3000 points with jittered, partly equal (and -0 / +0) times in scan order: neither sorted
  // nor two sorted runs, so the general ordering runs.
  LidarScan scan;
  scan.num_beams = 4;
  scan.has_ring = scan.has_time = true;
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> jitter(-40, 40);
  for (int k = 0; k < 3000; ++k)
    for (int r = 0; r < 4; ++r) {
      LidarPoint p;
      const float az = 0.002f * static_cast<float>(k);
      p.p = {8.0f * std::cos(az), 8.0f * std::sin(az), 0.3f * static_cast<float>(r)};
      p.ring = static_cast<std::uint16_t>(r);
      p.dt = std::min(0.0f, -0.1f + 1e-5f * static_cast<float>(std::clamp(3 * k + jitter(rng), 0, 9990) / 10 * 10));
      if (k % 500 == 0) p.dt = (k / 500) % 2 ? -0.0f : 0.0f;
      p.intensity = static_cast<float>(k);  // identifies the point
      scan.points.push_back(p);
    }
  PreprocessConfig cfg;
  cfg.outlier_min_neighbors = 0;  // only the ordering
  features::PreprocessReport rep;
  const features::RingCloud cloud = features::preprocessScan(scan, cfg, &rep);
  ASSERT_EQ(cloud.points.size(), scan.points.size());
  for (int r = 0; r < 4; ++r) {
    std::vector<LidarPoint> ring;
    for (const LidarPoint& p : scan.points)
      if (p.ring == r) ring.push_back(p);
    std::stable_sort(ring.begin(), ring.end(), [](const LidarPoint& a, const LidarPoint& b) { return a.dt < b.dt; });
    ASSERT_EQ(cloud.ringSize(r), static_cast<int>(ring.size()));
    for (std::size_t k = 0; k < ring.size(); ++k)
      ASSERT_TRUE(sameBits(cloud.points[cloud.ring_begin[r] + static_cast<int>(k)], ring[k])) << "ring " << r << " point " << k;
  }
}

}  // namespace
}  // namespace adit
