// featureConfigFrom: dotted keys override the documented defaults; missing keys keep them.
#include "features/feature_config.hpp"

#include <gtest/gtest.h>

namespace adit {
namespace {

TEST(FeatureConfig, ReadsDottedKeysAndKeepsDefaults) {
  const Config c = Config::fromYamlString(R"(
features:
  preprocess:
    min_range: 1.0
    body_box_min: [-1.0, -0.5, -0.5]
    body_box_max: [0.2, 0.5, 0.3]
    clockwise: false
  deskew:
    imu_rotation_rpy_deg: [180, 0, 90]
  loam:
    edge_threshold: 0.4
    sectors: 8
  link3d:
    min_cluster_points: 12
    edge_min_offset: 0.08
  ransac:
    seed: 7
)");
  const FeatureConfig f = featureConfigFrom(c);
  const FeatureConfig d;
  EXPECT_FLOAT_EQ(f.preprocess.min_range, 1.0f);
  EXPECT_FLOAT_EQ(f.preprocess.max_range, d.preprocess.max_range);
  EXPECT_TRUE(f.preprocess.body_box_min.isApprox(Eigen::Vector3f(-1.0f, -0.5f, -0.5f)));
  EXPECT_TRUE(f.preprocess.body_box_max.isApprox(Eigen::Vector3f(0.2f, 0.5f, 0.3f)));
  EXPECT_FALSE(f.preprocess.clockwise);
  const Eigen::Quaterniond expected = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX());
  EXPECT_NEAR(f.deskew.R_lidar_imu.angularDistance(expected), 0.0, 1e-6);
  EXPECT_FLOAT_EQ(f.loam.edge_threshold, 0.4f);
  EXPECT_EQ(f.loam.sectors, 8);
  EXPECT_EQ(f.loam.half_window, d.loam.half_window);
  EXPECT_EQ(f.link3d.min_cluster_points, 12);
  EXPECT_FLOAT_EQ(f.link3d.edge_min_offset, 0.08f);
  EXPECT_EQ(f.link3d.sectors, 120);
  EXPECT_EQ(f.ransac.seed, 7u);
  EXPECT_EQ(f.ransac.iterations, d.ransac.iterations);
}

TEST(FeatureConfig, RejectsMalformedValues) {
  EXPECT_THROW(featureConfigFrom(Config::fromYamlString("features:\n  loam:\n    sectors: six\n")), std::runtime_error);
  EXPECT_THROW(featureConfigFrom(Config::fromYamlString("features:\n  preprocess:\n    body_box_min: [1, 2]\n")),
               std::runtime_error);
}

}  // namespace
}  // namespace adit
