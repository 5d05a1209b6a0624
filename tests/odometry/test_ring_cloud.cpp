// RingIndexedCloud's ring queries (an outward walk in azimuth order that stops where the azimuth alone puts
// the rest beyond the k-th best) against a brute-force search over the ring, on sweeps with near walls, far
// points, points next to the vertical axis and at the azimuth seam (+-pi).
#include "odometry/ring_cloud.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>

namespace adit {
namespace {

float squaredDistance(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  float s = 0.0f;
  for (int i = 0; i < 3; ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
  return s;
}

// The k nearest of `ring` below max_sq, as (squared distance, index), nearest first.
std::vector<std::pair<float, int>> bruteForce(const RingIndexedCloud& c, int ring, const Eigen::Vector3d& q, int k,
                                              double max_sq, int exclude) {
  std::vector<std::pair<float, int>> all;
  for (int i = 0; i < static_cast<int>(c.size()); ++i) {
    if (c.ring(i) != ring || i == exclude) continue;
    const float d = squaredDistance(c.point(i).cast<float>(), q.cast<float>());
    if (d < static_cast<float>(max_sq)) all.push_back({d, i});
  }
  std::sort(all.begin(), all.end());
  all.resize(std::min<std::size_t>(all.size(), static_cast<std::size_t>(k)));
  return all;
}

// The ring's nearest point to q (excluded in the exclude test, so the answer is the next one), or -1.
int expectedExclude(const RingIndexedCloud& c, int ring, const Eigen::Vector3d& q, double max_sq) {
  const auto nearest = bruteForce(c, ring, q, 1, max_sq, -1);
  return nearest.empty() ? -1 : nearest[0].second;
}

std::vector<LidarPoint> sweep(std::mt19937& rng) {
  std::uniform_real_distribution<float> azimuth(-static_cast<float>(M_PI), static_cast<float>(M_PI)), unit(0.0f, 1.0f);
  std::vector<LidarPoint> points;
  for (int ring = 0; ring < 16; ++ring) {
    const float elevation = (-15.0f + 2.0f * ring) * static_cast<float>(M_PI / 180.0);
    for (int i = 0; i < 300; ++i) {
      const float a = i == 0 ? static_cast<float>(M_PI) : (i == 1 ? -static_cast<float>(M_PI) : azimuth(rng));
      const float u = unit(rng);
      const float range = u < 0.4f ? 1.0f + 2.0f * unit(rng) : (u < 0.45f ? 0.05f * unit(rng) : 5.0f + 55.0f * unit(rng));
      LidarPoint p;
      p.p = Eigen::Vector3f(range * std::cos(elevation) * std::cos(a), range * std::cos(elevation) * std::sin(a),
                            range * std::sin(elevation));
      p.ring = static_cast<std::uint16_t>(ring);
      points.push_back(p);
    }
  }
  return points;
}

TEST(RingIndexedCloud, RingQueriesEqualABruteForceSearch) {
  std::mt19937 rng(7);
  const std::vector<LidarPoint> points = sweep(rng);
  const RingIndexedCloud cloud(points);
  ASSERT_EQ(cloud.size(), points.size());
  std::normal_distribution<double> jitter(0.0, 0.3);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(points.size()) - 1);
  int compared = 0, found = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    Eigen::Vector3d q = cloud.point(pick(rng)) + Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
    if (trial % 10 == 0) q = Eigen::Vector3d(jitter(rng) * 0.01, jitter(rng) * 0.01, jitter(rng));  // at the axis
    const int ring = trial % 17;  // 16: a ring without points
    for (const double max_sq : {0.04, 9.0, 1e6}) {
      for (const int k : {1, 3, 5}) {
        const auto expected = bruteForce(cloud, ring, q, k, max_sq, -1);
        const std::vector<int> got = cloud.nearestKInRing(ring, q, k, max_sq);
        ASSERT_EQ(got.size(), expected.size()) << "trial " << trial << " k " << k << " bound " << max_sq;
        for (std::size_t i = 0; i < got.size(); ++i)
          EXPECT_EQ(got[i], expected[i].second) << "trial " << trial << " k " << k << " bound " << max_sq;
        ++compared;
        found += !got.empty();
      }
      const int exclude = expectedExclude(cloud, ring, q, max_sq);
      const auto expected = bruteForce(cloud, ring, q, 1, max_sq, exclude);
      EXPECT_EQ(cloud.nearestInRing(ring, q, max_sq, exclude), expected.empty() ? -1 : expected[0].second);
    }
  }
  EXPECT_GT(found, compared / 2);  // the queries do find points: the comparison is not of empty answers
}

}  // namespace
}  // namespace adit

namespace adit {
namespace {

// A corrupt message can carry any 16-bit ring number: only rings that hold points are kept, and each is found.
TEST(RingIndexedCloud, FarApartRingNumbersAreFoundAndGapsAreEmpty) {
  std::vector<LidarPoint> points(3);
  points[0].p = Eigen::Vector3f(5.0f, 0.0f, 0.0f);
  points[0].ring = 0;
  points[1].p = Eigen::Vector3f(5.0f, 0.1f, 0.0f);
  points[1].ring = 65535;
  points[2].p = Eigen::Vector3f(-5.0f, 0.0f, 0.0f);
  points[2].ring = 65535;
  const RingIndexedCloud cloud(points);
  const Eigen::Vector3d q(5.0, 0.05, 0.0);
  EXPECT_EQ(cloud.nearestInRing(0, q, 1.0, -1), 0);
  EXPECT_EQ(cloud.nearestInRing(65535, q, 1.0, -1), 1);
  EXPECT_EQ(cloud.nearestKInRing(65535, q, 5, 1e3), (std::vector<int>{1, 2}));
  EXPECT_EQ(cloud.nearestInRing(30000, q, 1e3, -1), -1);
  EXPECT_EQ(cloud.nearestInRing(-1, q, 1e3, -1), -1);
}

}  // namespace
}  // namespace adit
