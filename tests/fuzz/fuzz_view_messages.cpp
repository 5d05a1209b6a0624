// Bus messages as adit view receives them from the LAN (RunDecoder: wire check, lcm-gen's decoder, values)
// into its run model, then what the browser is sent from that model: trajectories, loops, the ground truth's
// alignment, the sweep and the submaps as binary frames (view/view_stream.hpp), each read back.
// Input: messages as [byte choosing the channel][uint16 size][bytes].
#include "fuzz_input.hpp"
#include "view/run_decoder.hpp"
#include "view/view_stream.hpp"

#include <spdlog/spdlog.h>

#include <cstdlib>

namespace {

void requireFrame(const std::string& bytes) {
  adit::view::DecodedFrame frame;
  if (!adit::view::decodeFrame(bytes, frame)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = (spdlog::set_level(spdlog::level::off), true);
  (void)quiet;
  using namespace adit::view;
  static const char* const kChannels[] = {"LIDAR_POINTS", "ODOM_MAPPED",    "GROUND_TRUTH",   "POSE_GRAPH", "LOOP_CLOSURE",
                                          "MAP_UPDATE",   "STATUS_mapper", "STATUS_feature", "IMU"};
  adit::fuzz::Input in(data, size);
  RunDecoder decoder;
  RunModel model;
  while (in.remaining() > 0) {
    const char* channel = kChannels[in.byte() % (sizeof(kChannels) / sizeof(kChannels[0]))];
    const std::string message = in.bytes(in.u16());
    decoder.apply(channel, reinterpret_cast<const std::uint8_t*>(message.data()), message.size(), model);
  }
  requireFrame(encodeTrajectory(TrajectoryKind::Odometry, true, model.odometry, 0));
  requireFrame(encodeTrajectory(TrajectoryKind::Corrected, true, model.correctedTrajectory(), 0));
  requireFrame(encodeTrajectory(TrajectoryKind::GroundTruth, true, model.groundTruthInWorld(), 0));
  requireFrame(encodeLoops(model.loopSegments()));
  requireFrame(encodeSweep(model.sweep, model.robot.pose, 6000));
  if (model.has_robot) requireFrame(encodeRobot(model.robot));
  for (const auto& [id, submap] : model.submaps) {
    requireFrame(encodeSubmap(submap));
    requireFrame(encodeSubmapPose(submap));
  }
  (void)model.distance();
  (void)model.mapPointCount();
  return 0;
}
