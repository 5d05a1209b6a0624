// Keyframe clouds kept as int16 counts (loop/compact_cloud.hpp): the round trip stays within half a step,
// far points coarsen the step instead of wrapping around, malformed stored clouds are refused; the store of a
// loop closer's clouds pages them to a file and reads back what it wrote.
#include "loop/compact_cloud.hpp"
#include "loop/keyframe_cloud_store.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <limits>
#include <random>

namespace adit {
namespace {

std::vector<Eigen::Vector3f> randomCloud(int n, float reach, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-reach, reach);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < n; ++i) points.emplace_back(u(rng), u(rng), u(rng) * 0.1f);
  return points;
}

void expectWithinHalfStep(const std::vector<Eigen::Vector3f>& in, const CompactCloud& c) {
  const std::vector<Eigen::Vector3f> out = c.decode();
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    // Half a step, plus the float rounding of a coordinate that far out (a few ulps).
    const float tolerance = c.step() * 0.5f + 4.0f * std::numeric_limits<float>::epsilon() * in[i].cwiseAbs().maxCoeff();
    ASSERT_LE((out[i] - in[i]).cwiseAbs().maxCoeff(), tolerance) << i << ": " << in[i].transpose();
  }
}

TEST(CompactCloud, RoundTripWithinHalfAStep) {
  const auto points = randomCloud(5000, 80.0f, 1);
  const CompactCloud c = CompactCloud::encode(points, 0.005f);
  EXPECT_FLOAT_EQ(c.step(), 0.005f);  // 80 m is within 32767 steps of 5 mm
  EXPECT_EQ(c.size(), points.size());
  EXPECT_EQ(c.bytes(), points.size() * 6);  // half of 3 floats
  expectWithinHalfStep(points, c);
}

// maxNorm, from the counts alone, bounds every decoded point and is no looser than the rounding margin.
TEST(CompactCloud, MaxNormBoundsEveryDecodedPoint) {
  for (const float reach : {0.5f, 40.0f, 300.0f}) {
    const CompactCloud c = CompactCloud::encode(randomCloud(2000, reach, 7), 0.005f);
    double farthest = 0.0;
    for (const Eigen::Vector3f& p : c.decode()) farthest = std::max(farthest, static_cast<double>(p.norm()));
    EXPECT_GE(c.maxNorm(), farthest) << reach;
    EXPECT_LE(c.maxNorm(), farthest * (1.0 + 1e-4)) << reach;
  }
  EXPECT_EQ(CompactCloud().maxNorm(), 0.0);
}

TEST(CompactCloud, FarPointsCoarsenTheStepInsteadOfOverflowing) {
  auto points = randomCloud(1000, 50.0f, 2);
  points.emplace_back(-400.0f, 0.0f, 1.0f);  // 80,000 steps of 5 mm: beyond int16
  const CompactCloud c = CompactCloud::encode(points, 0.005f);
  EXPECT_GE(c.step(), 400.0f / 32767.0f);
  EXPECT_LT(c.step(), 0.0125f);
  expectWithinHalfStep(points, c);
  EXPECT_NEAR(c.decode().back().x(), -400.0f, c.step());
}

TEST(CompactCloud, DropsNonFinitePointsAndHandlesEmpty) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const std::vector<Eigen::Vector3f> points{{1, 2, 3}, {nan, 0, 0}, {0, inf, 0}, {-1, -2, -3}};
  const CompactCloud c = CompactCloud::encode(points, 0.001f);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_TRUE(c.decode()[1].isApprox(Eigen::Vector3f(-1, -2, -3), 1e-3f));
  EXPECT_TRUE(CompactCloud::encode({}, 0.005f).decode().empty());
}

TEST(CompactCloud, StoredCountsOfBadSizeOrStepAreRefused) {
  EXPECT_FALSE(CompactCloud::fromCounts(0.005f, {1, 2, 3, 4}));  // not whole points
  EXPECT_FALSE(CompactCloud::fromCounts(0.005f, {1}));
  EXPECT_FALSE(CompactCloud::fromCounts(0.0f, {1, 2, 3}));
  EXPECT_FALSE(CompactCloud::fromCounts(-0.005f, {1, 2, 3}));
  EXPECT_FALSE(CompactCloud::fromCounts(std::numeric_limits<float>::quiet_NaN(), {1, 2, 3}));
  EXPECT_FALSE(CompactCloud::fromCounts(std::numeric_limits<float>::infinity(), {1, 2, 3}));
  const auto ok = CompactCloud::fromCounts(0.01f, {100, -200, 300});
  ASSERT_TRUE(ok);
  ASSERT_EQ(ok->decode().size(), 1u);
  EXPECT_TRUE(ok->decode()[0].isApprox(Eigen::Vector3f(1.0f, -2.0f, 3.0f)));
  // What encode() produced comes back identical through the stored form.
  const CompactCloud c = CompactCloud::encode(randomCloud(100, 30.0f, 3), 0.005f);
  const auto again = CompactCloud::fromCounts(c.step(), c.counts());
  ASSERT_TRUE(again);
  EXPECT_EQ(again->decode(), c.decode());
}

}  // namespace
}  // namespace adit

// --- KeyframeCloudStore: the loop closer's clouds, in memory or paged to a file ---

namespace {

adit::CompactCloud cloudOf(int k) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 50 + k; ++i) points.emplace_back(0.1f * static_cast<float>(i), static_cast<float>(k), -1.0f);
  return adit::CompactCloud::encode(points, 0.005f);
}

}  // namespace

TEST(KeyframeCloudStore, PagedCloudsReadBackAsWritten) {
  adit::KeyframeCloudStore store;
  for (int k = 0; k < 5; ++k) store.add(cloudOf(k));
  const std::string path = ::testing::TempDir() + "store_test.clouds";
  store.pageTo(path, 3);
  EXPECT_FALSE(std::filesystem::exists(path)) << "the page file is unlinked at once";
  for (int k = 5; k < 20; ++k) store.add(cloudOf(k));
  store.drop(7);
  EXPECT_EQ(store.pagedClouds(), 17u);
  EXPECT_EQ(store.size(), 20u);
  for (int k = 0; k < 20; ++k) {
    if (k == 7) {
      EXPECT_TRUE(store.empty(k));
      EXPECT_TRUE(store.cloud(k).empty());
      continue;
    }
    EXPECT_FALSE(store.empty(k));
    EXPECT_EQ(store.cloud(k).counts(), cloudOf(k).counts()) << k;
    EXPECT_EQ(store.cloud(k).step(), cloudOf(k).step()) << k;
  }
  // Moved, and paged again to a new file: nothing lost.
  adit::KeyframeCloudStore moved = std::move(store);
  moved.pageTo(path + "2", 1);
  for (int k = 0; k < 20; ++k) {
    if (k != 7) {
      EXPECT_EQ(moved.cloud(k).counts(), cloudOf(k).counts()) << k;
    }
  }
  EXPECT_EQ(moved.readErrors(), 0u);
  EXPECT_LT(moved.residentBytes(), 4096u) << "one cloud and the per-keyframe slots";
}

TEST(KeyframeCloudStore, KeypointsArePagedWithTheirCloud) {
  const auto keypointsOf = [](int k) {
    std::vector<Eigen::Vector3f> points;
    std::vector<adit::LinK3dDescriptor> descriptors;
    for (int i = 0; i < 3 + k % 4; ++i) {
      points.emplace_back(static_cast<float>(k), static_cast<float>(i), 0.5f);
      adit::LinK3dDescriptor d{};
      d[static_cast<std::size_t>((k + i) % d.size())] = 1.25f + 0.01f * static_cast<float>(i);
      descriptors.push_back(d);
    }
    return std::make_shared<const adit::KeyframeKeypoints>(adit::KeyframeKeypoints::encode(points, descriptors));
  };
  adit::KeyframeCloudStore store;
  store.pageTo(::testing::TempDir() + "store_keypoints.clouds", 2);
  for (int k = 0; k < 8; ++k) store.add(cloudOf(k), k == 5 ? nullptr : keypointsOf(k));
  store.drop(3);
  EXPECT_EQ(store.pagedClouds(), 6u);  // 0-5 (3 dropped after it went out)
  for (int k = 0; k < 8; ++k) {
    const adit::KeyframeKeypointsPtr p = store.keypoints(k);
    if (k == 3 || k == 5) {
      EXPECT_EQ(p, nullptr) << k;
      continue;
    }
    ASSERT_NE(p, nullptr) << k;
    EXPECT_EQ(p->points(), keypointsOf(k)->points()) << k;
    EXPECT_EQ(p->descriptors(), keypointsOf(k)->descriptors()) << k;
    EXPECT_EQ(store.cloud(k).counts(), cloudOf(k).counts()) << k;
  }
  EXPECT_EQ(store.readErrors(), 0u);
}

TEST(KeyframeCloudStore, AFailedPageWriteKeepsTheCloudInMemory) {
  // A file size limit makes every write to the page file fail (EFBIG), as a full disk would.
  std::signal(SIGXFSZ, SIG_IGN);
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  rlimit tiny = old;
  tiny.rlim_cur = 100;  // bytes: less than one cloud
  adit::KeyframeCloudStore store;
  store.pageTo(::testing::TempDir() + "store_full.clouds", 0);
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &tiny), 0);
  for (int k = 0; k < 4; ++k) store.add(cloudOf(k));
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &old), 0);
  EXPECT_GE(store.pageErrors(), 1u);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(store.cloud(k).counts(), cloudOf(k).counts()) << k;
  store.add(cloudOf(4));  // the limit lifted: the backlog goes out
  EXPECT_EQ(store.pagedClouds(), 5u);
  for (int k = 0; k < 5; ++k) EXPECT_EQ(store.cloud(k).counts(), cloudOf(k).counts()) << k;
}

TEST(KeyframeCloudStore, AnUncreatablePageFileThrows) {
  adit::KeyframeCloudStore store;
  store.add(cloudOf(0));
  EXPECT_THROW(store.pageTo("/nonexistent-folder/x.clouds", 0), std::runtime_error);
  EXPECT_EQ(store.cloud(0).counts(), cloudOf(0).counts());
}
