// The two PointCloud2 layouts the rosbag tests write, with the points they hold.
#pragma once

#include "bag_writer.hpp"

namespace adit::test {

struct TestCloud {
  Bytes message;                     // serialised sensor_msgs/PointCloud2
  std::vector<LidarPoint> expected;  // ring 0 = lowest, dt relative to the last firing
  std::int64_t expected_utime = 0;   // the last firing
};

// Velodyne driver layout: x y z intensity float32, ring uint16, time float32 seconds relative to the
// header stamp (<= 0: the stamp is the sweep's end). 16 rings x `columns` points.
TestCloud velodyneCloud(std::uint32_t sec, std::uint32_t nsec, int columns, unsigned salt);
// Ouster driver layout: x y z float32, 4 bytes padding, intensity float32, t uint32 ns after the stamp
// (the sweep's start), reflectivity uint16, ring uint8 (0 = top beam, as Ouster numbers them), ambient
// uint16, range uint32, 48-byte points, organised 16 rows with `row_padding` bytes after each row.
TestCloud ousterCloud(std::uint32_t sec, std::uint32_t nsec, int columns, unsigned salt, std::uint32_t row_padding = 0);

}  // namespace adit::test
