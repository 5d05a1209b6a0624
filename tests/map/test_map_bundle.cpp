// Map bundle (issue 18): a written bundle reads back exactly; a bad one (missing file, truncated, corrupt,
// another version, another sensor configuration, not a bundle) is refused with an error naming what is wrong.
#include "map/map_bundle.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace adit {
namespace {
namespace fs = std::filesystem;

// A small bundle: keyframes 1 m apart along x, each with a cloud of a 4 m wide box section and its Scan Context.
MapBundle sampleBundle() {
  MapBundle b;
  for (int k = 0; k < 6; ++k) {
    std::vector<Eigen::Vector3f> points;
    for (int i = 0; i < 200; ++i) {
      const float x = -10.0f + 0.1f * static_cast<float>(i), z = static_cast<float>(i % 7) * 0.3f - 1.0f;
      points.emplace_back(x, 2.0f + 0.01f * static_cast<float>(k), z);
      points.emplace_back(x, -2.0f, z + 0.05f * static_cast<float>(k));
    }
    BundleKeyframe kf;
    kf.utime = 1700000000000000 + k * 1000000;
    kf.pose.translation() = Eigen::Vector3d(k, 0.1 * k, 0.0);
    kf.pose.linear() = Eigen::AngleAxisd(0.05 * k, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    kf.cloud = CompactCloud::encode(points, 0.005f);
    kf.context = ScanContext::build(points, ScanContextConfig{});
    b.graph.addNode(kf.pose);
    if (k > 0) b.graph.addOdometryEdge(k - 1, k, b.keyframes.back().pose.inverse() * kf.pose, Matrix6d::Identity());
    b.keyframes.push_back(std::move(kf));
    b.map.insert(b.map.end(), points.begin(), points.end());
  }
  b.config = {{"features.preprocess.num_rings", "16"}, {"loop.scan_context.rings", "20"}, {"mapping.voxel", "0.1"}};
  b.summary.created = "2023-11-14T22:13:25Z";
  b.summary.keyframes = 6;
  b.summary.extent_max = Eigen::Vector3d(5, 0.5, 0);
  b.summary.roadway_length_m = 5.0;
  b.summary.map_voxel = 0.1;
  b.summary.sensor = bundleSensorKeys(b.config);
  return b;
}

class MapBundleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("adit_map_bundle_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    dir_ = (root_ / "bundle").string();
    writeMapBundle(sampleBundle(), dir_);
  }
  void TearDown() override { fs::remove_all(root_); }

  std::string file(const std::string& name) const { return (fs::path(dir_) / name).string(); }
  // The error loading the bundle gives ("" if it loads).
  std::string loadError() const {
    try {
      loadMapBundle(dir_);
    } catch (const BundleError& e) {
      return e.what();
    }
    return "";
  }
  void replaceInFile(const std::string& name, const std::string& from, const std::string& to) const {
    std::ifstream in(file(name));
    std::stringstream s;
    s << in.rdbuf();
    std::string text = s.str();
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(file(name), std::ios::trunc) << text;
  }

  fs::path root_;
  std::string dir_;
};

TEST_F(MapBundleTest, RoundTripsKeyframesGraphAndConfig) {
  const MapBundle in = sampleBundle();
  const MapBundle out = loadMapBundle(dir_);
  EXPECT_EQ(out.summary.version, kMapBundleVersion);
  EXPECT_EQ(out.summary.created, in.summary.created);
  EXPECT_EQ(out.summary.keyframes, 6);
  EXPECT_DOUBLE_EQ(out.summary.roadway_length_m, 5.0);
  EXPECT_EQ(out.summary.sensor, in.summary.sensor);
  EXPECT_EQ(out.summary.files.size(), 4u);
  EXPECT_EQ(out.config, in.config);
  ASSERT_EQ(out.keyframes.size(), in.keyframes.size());
  for (std::size_t k = 0; k < in.keyframes.size(); ++k) {
    EXPECT_EQ(out.keyframes[k].utime, in.keyframes[k].utime);
    EXPECT_TRUE(out.keyframes[k].pose.isApprox(in.keyframes[k].pose, 1e-12));
    EXPECT_EQ(out.keyframes[k].cloud.counts(), in.keyframes[k].cloud.counts());
    EXPECT_EQ(out.keyframes[k].context.descriptor(), in.keyframes[k].context.descriptor());
    EXPECT_NEAR(out.keyframes[k].context.distance(in.keyframes[k].context).first, 0.0, 1e-6);
  }
  ASSERT_EQ(out.graph.size(), in.graph.size());
  EXPECT_EQ(out.graph.edges().size(), in.graph.edges().size());
  for (int k = 0; k < in.graph.size(); ++k) EXPECT_TRUE(out.graph.pose(k).isApprox(in.graph.pose(k), 1e-6));
}

TEST_F(MapBundleTest, RewritingReplacesTheWholeFolderAndLeavesNoTemporaries) {
  MapBundle smaller = sampleBundle();
  smaller.keyframes.resize(3);
  smaller.summary.keyframes = 3;
  writeMapBundle(smaller, dir_);
  EXPECT_EQ(loadMapBundle(dir_).keyframes.size(), 3u);
  int entries = 0;
  for (const auto& e : fs::directory_iterator(root_)) entries += e.path().filename() == "bundle" ? 1 : 100;
  EXPECT_EQ(entries, 1);  // only the bundle: no .tmp / .old folders left
}

TEST_F(MapBundleTest, MissingFileIsNamed) {
  fs::remove(file("keyframes.bin"));
  EXPECT_NE(loadError().find("missing keyframes.bin"), std::string::npos) << loadError();
}

TEST_F(MapBundleTest, MissingManifestIsNamed) {
  fs::remove(file("manifest.yaml"));
  EXPECT_NE(loadError().find("no manifest.yaml"), std::string::npos) << loadError();
}

TEST_F(MapBundleTest, TruncatedFileIsNamed) {
  fs::resize_file(file("map.pcd"), fs::file_size(file("map.pcd")) / 2);
  EXPECT_NE(loadError().find("map.pcd holds"), std::string::npos) << loadError();
  EXPECT_NE(loadError().find("truncated"), std::string::npos) << loadError();
}

TEST_F(MapBundleTest, CorruptByteFailsTheChecksum) {
  {
    std::fstream f(file("keyframes.bin"), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(100);
    f.put('\x5a');
  }
  EXPECT_NE(loadError().find("keyframes.bin does not match its checksum"), std::string::npos) << loadError();
}

TEST_F(MapBundleTest, OtherVersionIsNamed) {
  replaceInFile("manifest.yaml", "version: 1", "version: 7");
  EXPECT_NE(loadError().find("version 7 bundle, this build reads version 1"), std::string::npos) << loadError();
}

TEST_F(MapBundleTest, NotABundleFolder) {
  dir_ = root_.string();
  EXPECT_NE(loadError().find("no manifest.yaml"), std::string::npos) << loadError();
  dir_ = (root_ / "nowhere").string();
  EXPECT_NE(loadError().find("not a map bundle folder"), std::string::npos) << loadError();
}

TEST_F(MapBundleTest, MalformedManifestValueIsNamed) {
  replaceInFile("manifest.yaml", "keyframes: 6", "keyframes: six");
  EXPECT_NE(loadError().find("'keyframes' is not a valid value"), std::string::npos) << loadError();
}

TEST_F(MapBundleTest, KeyframeCountDisagreeingWithTheManifestIsNamed) {
  replaceInFile("manifest.yaml", "keyframes: 6", "keyframes: 9");
  EXPECT_NE(loadError().find("holds 6 keyframes, the manifest says 9"), std::string::npos) << loadError();
}

TEST_F(MapBundleTest, OtherSensorConfigurationIsNamed) {
  const BundleSummary summary = readBundleSummary(dir_);
  EXPECT_EQ(bundleSensorMismatch(summary, {{"features.preprocess.num_rings", "16"}, {"mapping.voxel", "0.4"}}), "");
  EXPECT_EQ(bundleSensorMismatch(summary, {{"features.preprocess.num_rings", "64"}}),
            "the bundle was made with features.preprocess.num_rings = 16, this run has 64");
}

TEST(RoadwayLength, CountsARevisitOnce) {
  std::vector<Eigen::Vector3d> lap;
  for (int i = 0; i <= 40; ++i) lap.emplace_back(10.0 * std::cos(i * M_PI / 20), 10.0 * std::sin(i * M_PI / 20), 0.0);
  const double once = roadwayLength(lap);
  std::vector<Eigen::Vector3d> twice = lap;
  twice.insert(twice.end(), lap.begin() + 1, lap.end());
  // The last steps of the lap end within the revisit radius (3 m) of its start: they are the revisit.
  EXPECT_NEAR(once, 2 * M_PI * 10.0, 3.5);
  EXPECT_NEAR(roadwayLength(twice), once, 1.0);
}

}  // namespace
}  // namespace adit
