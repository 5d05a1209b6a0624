// ROS 1 message bodies (the serialisation rosbag stores) decoded into adit types, without ROS:
// sensor_msgs/PointCloud2 into a LidarScan, sensor_msgs/Imu into an ImuSample.
//
// ROS 1 serialisation: little-endian, no padding; string = uint32 length + bytes; variable array =
// uint32 count + elements; fixed array = elements; time = uint32 secs + uint32 nsecs.
//
// PointCloud2: any field layout. The fields become a PcdCloud and go through the PCD importer's
// conversion (pcd.hpp: x/y/z float32 or float64, intensity of any type, `ring` of any integer type,
// per-point time from the first of `time`, `t`, `timestamp`; integer types are nanoseconds, float types
// seconds; without a ring field, rings by elevation from the configured sensor profile). Time:
//  - per-point times above 1e6 s are absolute (Hesai, RoboSense `timestamp`): utime = the largest;
//  - smaller ones are offsets from the header stamp, as every driver writes them (Velodyne `time` <= 0
//    with the stamp at the sweep's end; Ouster `t` >= 0 ns and Livox-converted offsets with the stamp
//    at its start): utime = stamp + the largest offset, the last firing;
//  - without usable times (none, all equal, float32 epoch seconds): utime = the header stamp.
// A header stamp of 0 (some converters leave it unset) is replaced by the bag's record time.
// Big-endian clouds, rows padded beyond width * point_step are repacked; a field past point_step,
// an unknown datatype, a data array shorter than the declared points: DecodeError.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "core/types.hpp"
#include "io/pcd.hpp"

namespace adit::io {

class DecodeError : public ReadError {
 public:
  using ReadError::ReadError;
};

struct RosStamp {
  std::uint32_t sec = 0, nsec = 0;
  std::int64_t utime() const { return static_cast<std::int64_t>(sec) * 1000000 + (nsec + 500) / 1000; }
};

// `fallback_utime`: used when the message's header stamp is 0. Throws DecodeError.
LidarScan decodePointCloud2(const std::uint8_t* data, std::size_t size, const PcdFolderConfig& config,
                            std::int64_t fallback_utime, PcdScanReport* report = nullptr);
ImuSample decodeImu(const std::uint8_t* data, std::size_t size, std::int64_t fallback_utime);

}  // namespace adit::io
