#include <gtest/gtest.h>

#include "io/imu_csv.hpp"
#include "temp_dir.hpp"

namespace adit::io {
namespace {

using test::TempDir;

TEST(ImuCsv, ReadsCommaAndSpaceLinesSkipsHeaderAndCountsBadLines) {
  TempDir dir;
  dir.write("imu.csv",
            "# recorded on the test bench\n"              // 1 comment
            "t,gx,gy,gz,ax,ay,az,mx,my,mz\n"              // 2 header
            "10.000, 0.1, 0.2, 0.3, 0.0, 0.0, 9.81\n"     // 3 ok, comma + spaces
            "10.005 0.1 0.2 0.3 0.0 0.0 9.81 20 -5 40\n"  // 4 ok, spaces, magnetometer
            "\n"                                           // 5 empty
            "10.010,0.1,0.2,0.3,0.0,0.0\n"                // 6 bad: 6 columns
            "10.015,0.1,abc,0.3,0.0,0.0,9.81\n"           // 7 bad: not a number
            "10.020,0.1,,0.3,0.0,0.0,9.81\n"              // 8 bad: empty field
            "10.025\tnan\t0.2\t0.3\t0\t0\t9.81\n"         // 9 bad: NaN
            "10.030,1,2,3,4,5,6\n"                        // 10 ok
            "10.028,1,2,3,4,5,6\n");                      // 11 ok but backwards
  const ImuCsvResult r = readImuCsv(dir.file("imu.csv"));
  ASSERT_EQ(r.samples.size(), 4u);
  EXPECT_TRUE(r.had_header);
  EXPECT_EQ(r.skipped_comments, 2);
  ASSERT_EQ(r.bad_lines.size(), 4u);
  EXPECT_EQ(r.bad_lines[0].line_number, 6);
  EXPECT_EQ(r.bad_lines[1].line_number, 7);
  EXPECT_EQ(r.bad_lines[2].line_number, 8);
  EXPECT_EQ(r.bad_lines[3].line_number, 9);
  EXPECT_EQ(r.backwards_stamps, 1);
  EXPECT_NE(r.badLineSummary().find("6 (6 columns"), std::string::npos) << r.badLineSummary();

  EXPECT_EQ(r.samples[0].utime, 10000000);
  EXPECT_EQ(r.samples[1].utime, 10005000);
  EXPECT_DOUBLE_EQ(r.samples[0].gyro.y(), 0.2);
  EXPECT_DOUBLE_EQ(r.samples[0].accel.z(), 9.81);
  EXPECT_FALSE(r.samples[0].magnetic_field.has_value());
  ASSERT_TRUE(r.samples[1].magnetic_field.has_value());
  EXPECT_NEAR(r.samples[1].magnetic_field->x(), 20e-6, 1e-15);  // microtesla -> tesla by default
  EXPECT_NEAR(r.samples[1].magnetic_field->z(), 40e-6, 1e-15);
}

TEST(ImuCsv, NanosecondTimestampsAndUnitScales) {
  TempDir dir;
  dir.write("imu.txt",
            "1611234567123456789 1 0 0 1 0 0\n"
            "1611234567133456789 0 2 0 0 1 0\n");
  ImuCsvConfig config;
  config.gyro_scale = M_PI / 180.0;  // file in deg/s
  config.accel_scale = 9.80665;      // file in g
  const ImuCsvResult r = readImuCsv(dir.file("imu.txt"), config);
  ASSERT_EQ(r.samples.size(), 2u);
  EXPECT_FALSE(r.had_header);
  EXPECT_TRUE(r.bad_lines.empty());
  // Epoch nanoseconds in a double carry ~0.25 us: the utime is exact to 1 us.
  EXPECT_NEAR(static_cast<double>(r.samples[0].utime), 1611234567123457.0, 1.0);
  EXPECT_EQ(r.samples[1].utime - r.samples[0].utime, 10000);
  EXPECT_NEAR(r.samples[0].gyro.x(), M_PI / 180.0, 1e-12);
  EXPECT_NEAR(r.samples[1].accel.y(), 9.80665, 1e-12);
}

TEST(ImuCsv, ConfigKeysOverrideDefaults) {
  Config c;
  c.set("imu_csv.gyro_scale", "2.5");
  const ImuCsvConfig config = imuCsvConfigFrom(c);
  EXPECT_DOUBLE_EQ(config.gyro_scale, 2.5);
  EXPECT_DOUBLE_EQ(config.accel_scale, 1.0);
  EXPECT_DOUBLE_EQ(config.mag_scale, 1e-6);
}

TEST(ImuCsv, MissingFileThrowsReadErrorNamingIt) {
  try {
    readImuCsv("/nonexistent/imu.csv");
    FAIL() << "expected ReadError";
  } catch (const ReadError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/imu.csv"), std::string::npos);
  }
}

TEST(ImuCsv, GarbageFileGivesNoSamplesAndEveryLineBad) {
  TempDir dir;
  dir.write("junk.csv", std::string("1 2 3\n\x01\x02\x03\xff\n4,5\n"));
  const ImuCsvResult r = readImuCsv(dir.file("junk.csv"));
  EXPECT_TRUE(r.samples.empty());
  EXPECT_EQ(r.bad_lines.size(), 3u);
}

}  // namespace
}  // namespace adit::io
