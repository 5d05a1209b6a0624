// Keyframe clouds kept as int16 counts (loop/compact_cloud.hpp): the round trip stays within half a step,
// far points coarsen the step instead of wrapping around, malformed stored clouds are refused.
#include "loop/compact_cloud.hpp"

#include <gtest/gtest.h>

#include <cmath>
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
