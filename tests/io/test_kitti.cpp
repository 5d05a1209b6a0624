#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "io/kitti.hpp"
#include "temp_dir.hpp"

namespace adit::io {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

const std::string kRoot = std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini";

TEST(Kitti, ListsScansAndReadsTimes) {
  const KittiSequence seq = KittiSequence::open(kRoot, "00");
  ASSERT_EQ(seq.size(), 10u);
  EXPECT_EQ(fs::path(seq.scanFiles().front()).filename(), "000000.bin");
  EXPECT_EQ(fs::path(seq.scanFiles().back()).filename(), "000009.bin");
  EXPECT_EQ(seq.utime(0), 0);
  EXPECT_EQ(seq.utime(1), 103736);  // times.txt: 1.037359e-01
  EXPECT_EQ(seq.utime(9), 933147);  // 9.331467e-01
  EXPECT_TRUE(seq.hasCalibration());
  EXPECT_NEAR(seq.calibration().P[0](0, 0), 718.856, 1e-9);
  EXPECT_NEAR(seq.calibration().T_cam0_velo.translation().z(), -0.2921968648686, 1e-12);
}

TEST(Kitti, ScanHasRawPointsAndMetadata) {
  const KittiSequence seq(kRoot + "/sequences/00");
  KittiScanReport report;
  const LidarScan scan = seq.scan(0, &report);
  ASSERT_EQ(scan.points.size(), 1994688u / 16u);
  const LidarPoint& first = scan.points.front();
  EXPECT_FLOAT_EQ(first.p.x(), 52.897942f);
  EXPECT_FLOAT_EQ(first.p.y(), 0.022989739f);
  EXPECT_FLOAT_EQ(first.p.z(), 1.9979945f);
  EXPECT_FLOAT_EQ(first.intensity, 0.08f);
  EXPECT_EQ(scan.sensor, "hdl64");
  EXPECT_EQ(scan.num_beams, 64);
  EXPECT_EQ(scan.seq, 0);
  EXPECT_TRUE(scan.has_ring);
  EXPECT_TRUE(scan.has_time);
  EXPECT_FALSE(scan.deskewed);
  EXPECT_FLOAT_EQ(scan.sweep_duration, 0.1f);
  EXPECT_EQ(report.ring_method, KittiRingMethod::kScanOrder);
  EXPECT_EQ(report.nan_points, 0);
  // The first stored point faces forward: mid-sweep.
  EXPECT_NEAR(first.dt, -0.05, 1e-4);
  for (const LidarPoint& pt : scan.points) {
    ASSERT_LE(pt.dt, 0.0f);
    ASSERT_GE(pt.dt, -0.1f);
  }
}

TEST(Kitti, PointTimesFollowACounterClockwiseSweepEndingBehind) {
  EXPECT_NEAR(kittiPointDt(-1.0f, 1e-6f), 0.0, 1e-6);    // just left of straight back: last firing
  EXPECT_NEAR(kittiPointDt(-1.0f, -1e-6f), -0.1, 1e-6);  // just right of it: first firing
  EXPECT_NEAR(kittiPointDt(0.0f, -1.0f), -0.075, 1e-6);  // right
  EXPECT_NEAR(kittiPointDt(1.0f, 0.0f), -0.05, 1e-6);    // front
  EXPECT_NEAR(kittiPointDt(0.0f, 1.0f), -0.025, 1e-6);   // left
}

// Median x of the points of one ring within an azimuth window (deg), after moving each point by v * dt.
double medianX(const LidarScan& scan, int ring, double az_lo, double az_hi, double v) {
  std::vector<double> xs;
  for (const LidarPoint& pt : scan.points) {
    const double az = std::atan2(pt.p.y(), pt.p.x()) * 180.0 / M_PI;
    if (pt.ring == ring && az > az_lo && az < az_hi) xs.push_back(pt.p.x() + v * pt.dt);
  }
  if (xs.empty()) return NAN;
  std::nth_element(xs.begin(), xs.begin() + xs.size() / 2, xs.end());
  return xs[xs.size() / 2];
}

// The dt convention checked against the data: the ground behind the car shows a seam of one scan's travel
// between azimuth +180 and -180; moving points by the true velocity times dt (into the lidar frame at
// the sweep end) must close it. The wrong spin direction would double it instead.
TEST(Kitti, DtClosesTheSeamBehindTheCar) {
  for (const char* name : {"00", "02"}) {
    const KittiSequence seq = KittiSequence::open(kRoot, name);
    const Trajectory gt = seq.groundTruthLidar(seq.defaultPosesFile());
    const double speed = (gt[1].pose.translation() - gt[0].pose.translation()).norm() / kKittiSweepDuration;
    const LidarScan scan = seq.scan(0);
    for (int ring : {13, 18}) {  // ground rings, 5-7 m behind
      const double raw = medianX(scan, ring, 176, 180, 0) - medianX(scan, ring, -180, -176, 0);
      const double fixed = medianX(scan, ring, 176, 180, speed) - medianX(scan, ring, -180, -176, speed);
      EXPECT_LT(raw, -0.6) << name << " ring " << ring;  // the +180 side was fired last, from farther ahead
      EXPECT_LT(std::abs(fixed), 0.25 * std::abs(raw)) << name << " ring " << ring << " raw " << raw;
    }
  }
}

TEST(Kitti, GroundTruthInLidarFrameMovesForwardAlongX) {
  for (const char* name : {"00", "01", "02"}) {
    const KittiSequence seq = KittiSequence::open(kRoot, name);
    const Trajectory gt = seq.groundTruthLidar(seq.defaultPosesFile());
    ASSERT_EQ(gt.size(), 10u);
    EXPECT_EQ(gt[3].utime, seq.utime(3));
    EXPECT_TRUE(gt[0].pose.isApprox(Eigen::Isometry3d::Identity(), 1e-6)) << name;
    for (size_t i = 1; i < gt.size(); ++i) {
      const Eigen::Vector3d step = gt[i - 1].pose.inverse() * gt[i].pose.translation();
      EXPECT_GT(step.x(), 0.6) << name << " " << i;  // README: 0.7-1.5 m per scan, forward = lidar x
      EXPECT_LT(step.x(), 1.7) << name << " " << i;
      EXPECT_LT(std::abs(step.y()), 0.1) << name << " " << i;
      EXPECT_LT(std::abs(step.z()), 0.1) << name << " " << i;
    }
  }
}

TEST(Kitti, ConvertsCameraPosesWithTheCalibration) {
  const KittiSequence seq = KittiSequence::open(kRoot, "00");
  const Trajectory gt = seq.groundTruthLidar(seq.defaultPosesFile());
  // poses/00.txt line 2: camera moved 0.8586941 m along its z (forward) and -0.0469 along x (right):
  // the lidar frame has x forward and y left, so that is ~+0.859 in x and ~+0.047 in y.
  EXPECT_NEAR(gt[1].pose.translation().x(), 0.8587, 0.02);
  EXPECT_NEAR(gt[1].pose.translation().y(), 0.0469, 0.02);
}

TEST(Kitti, MissingTimesFileIsAnErrorNamingIt) {
  TempDir dir;
  fs::create_directories(dir.file("velodyne"));
  fs::copy_file(kRoot + "/sequences/00/velodyne/000000.bin", dir.file("velodyne/000000.bin"));
  try {
    KittiSequence seq(dir.path());
    FAIL() << "expected ReadError";
  } catch (const ReadError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.file("times.txt")), std::string::npos) << e.what();
  }
}

TEST(Kitti, TruncatedScanIsAnErrorNamingIt) {
  TempDir dir;
  fs::create_directories(dir.file("velodyne"));
  dir.write("times.txt", "0.0\n0.1\n");
  const std::string bytes = test::readAll(kRoot + "/sequences/00/velodyne/000000.bin");
  dir.write("velodyne/000000.bin", bytes.substr(0, 16 * 1000));
  dir.write("velodyne/000001.bin", bytes.substr(0, 16 * 1000 + 7));
  const KittiSequence seq(dir.path());
  ASSERT_EQ(seq.size(), 2u);
  EXPECT_FALSE(seq.hasCalibration());
  EXPECT_THROW(seq.calibration(), ReadError);
  EXPECT_EQ(seq.scan(0).points.size(), 1000u);  // a whole number of points reads fine
  try {
    seq.scan(1);
    FAIL() << "expected ReadError";
  } catch (const ReadError& e) {
    EXPECT_NE(std::string(e.what()).find("000001.bin"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("16007"), std::string::npos) << e.what();
  }
}

TEST(Kitti, ScanDeletedAfterOpeningIsAnErrorNamingIt) {
  TempDir dir;
  fs::create_directories(dir.file("velodyne"));
  dir.write("times.txt", "0.0\n");
  dir.write("velodyne/000000.bin", std::string(32, '\0'));
  const KittiSequence seq(dir.path());
  fs::remove(dir.file("velodyne/000000.bin"));
  try {
    seq.scan(0);
    FAIL() << "expected ReadError";
  } catch (const ReadError& e) {
    EXPECT_NE(std::string(e.what()).find("000000.bin"), std::string::npos) << e.what();
  }
  EXPECT_THROW(seq.scan(5), ReadError);
}

TEST(Kitti, ShortOrCorruptTimesFileIsAnError) {
  TempDir dir;
  fs::create_directories(dir.file("velodyne"));
  dir.write("velodyne/000000.bin", std::string(16, '\0'));
  dir.write("velodyne/000001.bin", std::string(16, '\0'));
  dir.write("times.txt", "0.0\n");
  EXPECT_THROW(KittiSequence seq(dir.path()), ReadError);
  dir.write("times.txt", "0.0\nzero point one\n");
  EXPECT_THROW(KittiSequence seq(dir.path()), ReadError);
}

TEST(Kitti, NanPointsAreKeptAndCounted) {
  TempDir dir;
  fs::create_directories(dir.file("velodyne"));
  dir.write("times.txt", "5.0\n");
  const float pts[8] = {1.0f, 2.0f, 0.5f, 0.3f, NAN, 0.0f, 0.0f, 0.0f};
  dir.write("velodyne/000000.bin", std::string(reinterpret_cast<const char*>(pts), sizeof(pts)));
  const KittiSequence seq(dir.path());
  KittiScanReport report;
  const LidarScan scan = seq.scan(0, &report);
  ASSERT_EQ(scan.points.size(), 2u);
  EXPECT_EQ(report.nan_points, 1);
  EXPECT_EQ(report.ring_method, KittiRingMethod::kNominalElevationTable);  // 2 points are not 64 rows
  EXPECT_EQ(scan.utime, 5000000);
}

// Issue 14: a bad times.txt said only "stol". The error names the file, the line and what is wrong.
TEST(Kitti, TimesErrorsNameTheFileTheLineAndTheProblem) {
  const auto errorFor = [](const std::string& text) {
    try {
      parseKittiTimes(text, "seq/times.txt");
    } catch (const ReadError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(errorFor("0.0\nzero point one\n"), "KITTI: 'seq/times.txt' line 2: 'zero point one' is not a time in seconds");
  EXPECT_EQ(errorFor("0.0\n0.1 0.2\n"), "KITTI: 'seq/times.txt' line 2: 2 numbers, expected one time in seconds");
  EXPECT_EQ(errorFor("-1.0\n"), "KITTI: 'seq/times.txt' line 1: negative time -1.000000");
  EXPECT_EQ(errorFor("0.2\n0.1\n"), "KITTI: 'seq/times.txt' line 2: time goes backwards (0.100000 after 0.200000)");
  EXPECT_EQ(errorFor("0.0\n\n0.1\n"), "");
  // Found by fuzz_kitti: a time of 1e300 s overflowed the conversion to utime (undefined behaviour).
  EXPECT_EQ(errorFor("0.0\n1e300\n"), "KITTI: 'seq/times.txt' line 2: time " + std::to_string(1e300) +
                                           " s is beyond the year 2286");
  EXPECT_EQ(parseKittiTimes("0.0\n\n1e-1\n", "t").size(), 2u);
}

TEST(Kitti, EmptyHugeAndOddSizedScansAreErrorsNamingTheFile) {
  TempDir dir;
  fs::create_directories(dir.file("velodyne"));
  dir.write("times.txt", "0.0\n0.1\n0.2\n");
  dir.write("velodyne/000000.bin", "");
  dir.write("velodyne/000001.bin", std::string(17, '\0'));
  dir.write("velodyne/000002.bin", "");
  fs::resize_file(dir.file("velodyne/000002.bin"), kKittiMaxScanBytes + 16);  // sparse: costs no disk
  const KittiSequence seq(dir.path());
  const auto errorOf = [&](std::size_t i) {
    try {
      seq.scan(i);
    } catch (const ReadError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(errorOf(0).find("000000.bin' is empty"), std::string::npos) << errorOf(0);
  EXPECT_NE(errorOf(1).find("000001.bin' is truncated or corrupt: 17 bytes"), std::string::npos) << errorOf(1);
  EXPECT_NE(errorOf(2).find("000002.bin' is 268435472 bytes, more than any sweep"), std::string::npos) << errorOf(2);
}

// A scan named by a number too long for a long (stol threw std::out_of_range): read in name order instead.
TEST(Kitti, OverlongNumericScanNameIsNotACrash) {
  TempDir dir;
  fs::create_directories(dir.file("velodyne"));
  dir.write("times.txt", "0.0\n");
  dir.write("velodyne/99999999999999999999999.bin", std::string(16, '\0'));
  const KittiSequence seq(dir.path());
  EXPECT_EQ(seq.scan(0).points.size(), 1u);
}

TEST(Kitti, MissingSequenceDirectoryIsAnError) {
  EXPECT_THROW(KittiSequence::open(kRoot, "99"), ReadError);
}

}  // namespace
}  // namespace adit::io
