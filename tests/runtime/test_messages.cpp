// Message round trips: stage types -> LCM message -> bytes -> LCM message -> stage types.
#include "msg/convert.hpp"

#include <gtest/gtest.h>

namespace {

template <class Msg>
Msg throughBytes(const Msg& in) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(in.getEncodedSize()));
  EXPECT_EQ(in.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  Msg out;
  EXPECT_EQ(out.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return out;
}

adit::LidarScan makeScan(int n) {
  adit::LidarScan s;
  s.utime = 1'700'000'000'123'456;
  s.seq = 42;
  s.sensor = "vlp16";
  s.num_beams = 16;
  s.sweep_duration = 0.1f;
  s.has_ring = s.has_time = true;
  for (int i = 0; i < n; ++i) {
    adit::LidarPoint p;
    p.p = Eigen::Vector3f(0.5f * i, -1.0f * i, 0.25f);
    p.intensity = static_cast<float>(i % 256);
    p.ring = static_cast<std::uint16_t>(i % 16);
    p.dt = -0.1f + 0.1f * static_cast<float>(i) / static_cast<float>(n);
    s.points.push_back(p);
  }
  return s;
}

void expectSamePoints(const std::vector<adit::LidarPoint>& a, const std::vector<adit::LidarPoint>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].p, b[i].p);
    EXPECT_EQ(a[i].intensity, b[i].intensity);
    EXPECT_EQ(a[i].ring, b[i].ring);
    EXPECT_EQ(a[i].dt, b[i].dt);
  }
}

}  // namespace

TEST(Messages, PointCloudRoundTrip) {
  const adit::LidarScan in = makeScan(100);
  const adit::LidarScan out = adit::msg::fromMessage(throughBytes(adit::msg::toMessage(in)));
  EXPECT_EQ(out.utime, in.utime);
  EXPECT_EQ(out.seq, in.seq);
  EXPECT_EQ(out.sensor, "vlp16");
  EXPECT_EQ(out.num_beams, 16);
  EXPECT_FLOAT_EQ(out.sweep_duration, 0.1f);
  EXPECT_TRUE(out.has_ring);
  EXPECT_TRUE(out.has_time);
  EXPECT_FALSE(out.deskewed);
  expectSamePoints(in.points, out.points);
}

TEST(Messages, ImuRoundTripKeepsOptionalFields) {
  adit::ImuSample in;
  in.utime = 123;
  in.gyro = {0.1, -0.2, 0.3};
  in.accel = {0.0, 0.1, 9.81};
  in.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  const adit::ImuSample out = adit::msg::fromMessage(throughBytes(adit::msg::toMessage(in)));
  EXPECT_EQ(out.utime, 123);
  EXPECT_EQ(out.gyro, in.gyro);
  EXPECT_EQ(out.accel, in.accel);
  EXPECT_FALSE(out.magnetic_field.has_value());
  ASSERT_TRUE(out.orientation.has_value());
  EXPECT_NEAR(out.orientation->angularDistance(*in.orientation), 0.0, 1e-12);
}

// FEATURES is lean (tests/msg has the quantisation figures): positions within half a count, rings on the LOAM
// sets, times only for a raw sweep, no intensity, descriptors within half of 2 mm.
namespace {
void expectLeanPoints(const std::vector<adit::LidarPoint>& a, const std::vector<adit::LidarPoint>& b, bool rings,
                      bool times) {
  ASSERT_EQ(a.size(), b.size());
  float largest = 0.0f;  // the set's scale: 1 mm, coarser if a coordinate exceeds 32.767 m
  for (const auto& p : a) largest = std::max(largest, p.p.cwiseAbs().maxCoeff());
  const float scale = std::max(adit::msg::kPointSetScale, largest / 32767.0f);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_LE((a[i].p - b[i].p).cwiseAbs().maxCoeff(), 0.5f * scale + 1e-6f);
    EXPECT_EQ(b[i].intensity, 0.0f);
    EXPECT_EQ(b[i].ring, rings ? a[i].ring : 0);
    EXPECT_EQ(b[i].dt, times ? a[i].dt : 0.0f);
  }
}
}  // namespace

TEST(Messages, FeatureSetRoundTrip) {
  for (const bool deskewed : {true, false}) {
    adit::FeatureSet in;
    in.utime = 5'000'000;
    in.cloud = makeScan(50);
    in.cloud.deskewed = deskewed;
    in.corner_sharp = makeScan(3).points;
    in.corner_less_sharp = makeScan(6).points;
    in.surf_flat = makeScan(4).points;
    in.surf_less_flat = makeScan(9).points;
    for (int k = 0; k < 7; ++k) {
      in.keypoints.emplace_back(1.0f * k, 2.0f, -3.0f);
      adit::LinK3dDescriptor d{};
      d[static_cast<std::size_t>(k * 10)] = 1.5f + 0.1234f * k;
      in.descriptors.push_back(d);
    }
    in.flags = adit::FeatureSet::kDeskewImu | adit::FeatureSet::kEmptyRing;
    in.points_in = 60;
    in.removed_invalid = 4;
    in.removed_range = 3;
    in.removed_outlier = 3;
    const adit::FeatureSet out = adit::msg::fromMessage(throughBytes(adit::msg::toMessage(in)));
    EXPECT_EQ(out.utime, in.utime);
    EXPECT_EQ(out.cloud.deskewed, deskewed);
    EXPECT_EQ(out.cloud.sensor, "vlp16");
    EXPECT_EQ(out.cloud.num_beams, 16);
    expectLeanPoints(in.cloud.points, out.cloud.points, false, !deskewed);
    expectLeanPoints(in.corner_sharp, out.corner_sharp, true, !deskewed);
    expectLeanPoints(in.corner_less_sharp, out.corner_less_sharp, true, !deskewed);
    expectLeanPoints(in.surf_flat, out.surf_flat, true, !deskewed);
    expectLeanPoints(in.surf_less_flat, out.surf_less_flat, true, !deskewed);
    EXPECT_EQ(out.keypoints, in.keypoints);
    ASSERT_EQ(out.descriptors.size(), in.descriptors.size());
    for (std::size_t k = 0; k < in.descriptors.size(); ++k)
      for (std::size_t b = 0; b < in.descriptors[k].size(); ++b) {
        EXPECT_NEAR(out.descriptors[k][b], in.descriptors[k][b], 0.5f * adit::msg::kDescriptorScale + 1e-6f);
        EXPECT_EQ(out.descriptors[k][b] == 0.0f, in.descriptors[k][b] == 0.0f);
      }
    EXPECT_EQ(out.flags, in.flags);
    EXPECT_EQ(out.points_in, 60);
    EXPECT_EQ(out.removed_invalid + out.removed_range + out.removed_outlier, 10);
  }
}

TEST(Messages, OdometryCarriesOnlyTheSetsTheMapperNeeds) {
  adit::FeatureSet f;
  f.cloud = makeScan(20);
  f.cloud.deskewed = true;
  f.corner_sharp = makeScan(3).points;  // odometry-only: never on ODOM_SCAN
  f.corner_less_sharp = makeScan(6).points;
  f.surf_less_flat = makeScan(9).points;
  adit::odometry_t m = throughBytes(adit::msg::toMessage(adit::PoseEstimate{}, &f));
  const adit::FeatureSet out = adit::msg::featuresOf(m);
  EXPECT_TRUE(out.cloud.deskewed);
  EXPECT_TRUE(out.corner_sharp.empty());
  expectLeanPoints(f.corner_less_sharp, out.corner_less_sharp, false, false);
  expectLeanPoints(f.surf_less_flat, out.surf_less_flat, false, false);
  expectLeanPoints(f.cloud.points, out.cloud.points, false, false);
  adit::msg::stripPoints(m);
  EXPECT_EQ(m.corners.num_points + m.surfaces.num_points + m.cloud.num_points, 0);
  // The pose alone: what the LAN and replay's output carry (630 bytes since ODOM_SCAN carries the accelerometer
  // preintegrated and ODOM_MAPPED gravity, 56 bytes; the covariance is 288 of them).
  EXPECT_LT(m.getEncodedSize(), 640);
}

TEST(Messages, OdometryRoundTripKeepsPoseAndCovariance) {
  adit::PoseEstimate in;
  in.utime = 77;
  in.pose = Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 0).normalized());
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) in.covariance(r, c) = 0.01 * (r + 1) + (r == c ? 1.0 : 0.0) + 0.001 * c;
  in.translation_eigenvalues = {1, 2, 3};
  in.rotation_eigenvalues = {4, 5, 6};
  in.flags = adit::PoseEstimate::kDegenerateTranslation | adit::PoseEstimate::kSeededByLinK3d;
  in.iterations = 9;
  in.final_cost = 0.5;
  const adit::PoseEstimate out = adit::msg::fromMessage(throughBytes(adit::msg::toMessage(in, nullptr)));
  EXPECT_EQ(out.utime, 77);
  EXPECT_TRUE(out.pose.isApprox(in.pose, 1e-12));
  EXPECT_EQ(out.covariance, in.covariance);
  EXPECT_EQ(out.translation_eigenvalues, in.translation_eigenvalues);
  EXPECT_EQ(out.rotation_eigenvalues, in.rotation_eigenvalues);
  EXPECT_EQ(out.flags, in.flags);
  EXPECT_EQ(out.iterations, 9);
}

TEST(Messages, LoopClosureRoundTrip) {
  adit::LoopConstraint in;
  in.query_index = 120;
  in.match_index = 3;
  in.query_utime = 120'000'000;
  in.match_utime = 3'000'000;
  in.T_match_query = Eigen::Translation3d(0.3, -0.2, 0.05) * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ());
  in.information = adit::Matrix6d::Identity() * 100.0;
  in.scan_context_distance = 0.12;
  in.scan_context_yaw = -0.4;
  in.fitness = 0.03;
  in.inlier_ratio = 0.9;
  const adit::LoopConstraint out = adit::msg::fromMessage(throughBytes(adit::msg::toMessage(in, in.query_utime)));
  EXPECT_EQ(out.query_index, 120);
  EXPECT_EQ(out.match_index, 3);
  EXPECT_EQ(out.match_utime, 3'000'000);
  EXPECT_TRUE(out.T_match_query.isApprox(in.T_match_query, 1e-12));
  EXPECT_EQ(out.information, in.information);
  EXPECT_DOUBLE_EQ(out.scan_context_yaw, -0.4);
}

TEST(Messages, TruncatedBytesFailToDecodeWithoutThrowing) {
  adit::point_cloud_t m = adit::msg::toMessage(makeScan(100));
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  adit::point_cloud_t out;
  EXPECT_LT(out.decode(bytes.data(), 0, static_cast<int>(bytes.size() / 2)), 0);
  adit::imu_t wrong_type;
  EXPECT_LT(wrong_type.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);  // fingerprint mismatch
}
