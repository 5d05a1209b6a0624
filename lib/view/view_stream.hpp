// The binary frames adit view sends to a browser over its WebSocket (one frame = one WebSocket binary
// message), little-endian, read by web/view/stream.js. First byte: the frame type.
//   Submap      u32 id, u32 version, pose, u32 n, n x (i16 x, y, z) at 1 cm in the keyframe frame
//   SubmapPose  u32 id, u32 version, pose                      (a loop moved it: its points are already there)
//   Sweep       i64 utime, pose, u32 n, n x (i16 x, y, z) at 1 cm in the lidar frame, n x u8 intensity
//   Trajectory  u8 kind (0 odometry, 1 corrected, 2 ground truth, 3 corrected keyframes), u8 replace (1) or append (0),
//               u32 n, n x (f32 x, y, z) world positions
//   Loops       u32 n, n x (f32 x, y, z, x, y, z): segments between the loop's corrected keyframes
//   Robot       i64 utime, pose
//   Info        UTF-8 JSON: STATUS rows, run facts, playback state, the server's counters
//   Reset       (nothing): forget everything (the log was rewound)
// pose = f64 x, y, z, f32 qx, qy, qz, qw. Coordinates beyond the i16 range (327 m) are left out.
#pragma once

#include "view/run_model.hpp"

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace adit::view {

enum class FrameType : std::uint8_t { Submap = 1, SubmapPose = 2, Sweep = 3, Trajectory = 4, Loops = 5, Robot = 6, Info = 7, Reset = 8 };
enum class TrajectoryKind : std::uint8_t { Odometry = 0, Corrected = 1, GroundTruth = 2, Keyframes = 3 };

constexpr float kPointScale = 0.01f;  // metres per i16 count

std::string encodeSubmap(const Submap& s);
std::string encodeSubmapPose(const Submap& s);
// At most max_points of the sweep (every k-th point), placed at `pose`.
std::string encodeSweep(const Sweep& sweep, const Eigen::Isometry3d& pose, std::size_t max_points);
std::string encodeTrajectory(TrajectoryKind kind, bool replace, const std::vector<TimedPose>& poses, std::size_t from);
std::string encodeLoops(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments);
std::string encodeRobot(const TimedPose& robot);
std::string encodeInfo(const std::string& json);
std::string encodeReset();

// The same frames decoded (the tests' view of what the page reads).
struct DecodedFrame {
  FrameType type = FrameType::Reset;
  std::uint32_t id = 0, version = 0;
  std::int64_t utime = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3f> points;
  std::vector<std::uint8_t> intensity;
  TrajectoryKind kind = TrajectoryKind::Odometry;
  bool replace = false;
  std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> segments;
  std::string json;
};
// False when the bytes are not a whole frame of a known type.
bool decodeFrame(const std::string& bytes, DecodedFrame& out);

}  // namespace adit::view
