#include "foxglove/foxglove_run.hpp"

#include "foxglove/foxglove_json.hpp"

#include <algorithm>

namespace adit::foxglove {
namespace {

SchemaText schemaNamed(const std::string& name) {
  if (name == "foxglove.PointCloud") return pointCloudSchema();
  if (name == "foxglove.FrameTransform") return frameTransformSchema();
  if (name == "foxglove.PosesInFrame") return posesInFrameSchema();
  if (name == "foxglove.SceneUpdate") return sceneUpdateSchema();
  return statusSchema();
}

bool due(std::int64_t now, std::int64_t last, double period_s) {
  return last < 0 || static_cast<double>(now - last) >= period_s * 1e6;
}

}  // namespace

FoxgloveRun::FoxgloveRun(FoxgloveSink& sink, ExportOptions options) : sink_(sink), options_(options) {}

void FoxgloveRun::publish(const std::string& topic, const std::string& schema, const std::string& json) {
  sink_.publish(topic, schemaNamed(schema), json, static_cast<std::uint64_t>(std::max<std::int64_t>(log_utime_, 0)) * 1000u);
  ++written_[topic];
}

void FoxgloveRun::add(const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t log_utime) {
  log_utime_ = log_utime;
  const unsigned changed = decoder_.apply(channel, data, size, model_);
  if (changed & view::kSweepChanged) {
    if (sweeps_seen_++ % std::max(1, options_.sweep_every) == 0)
      publish("/lidar/points", "foxglove.PointCloud",
              pointCloudJson(model_.sweep.utime, "lidar", model_.sweep.points, &model_.sweep.intensity));
  }
  if (changed & view::kOdometryChanged) {
    publish("/tf", "foxglove.FrameTransform",
            frameTransformJson(model_.robot.utime, "world", "lidar", model_.robot.pose));
    trajectories_pending_ = true;
  }
  if (changed & view::kGroundTruthChanged) {
    const view::TimedPose& gt = model_.ground_truth.back();
    publish("/tf", "foxglove.FrameTransform",
            frameTransformJson(gt.utime, "world", "ground_truth", model_.groundTruthAlignment() * gt.pose));
    trajectories_pending_ = true;
  }
  if (changed & (view::kKeyframesChanged | view::kLoopsChanged)) {
    trajectories_pending_ = true;
    if (!model_.loops.empty())
      publish("/loops", "foxglove.SceneUpdate", lineListSceneJson(log_utime, "world", "loops", model_.loopSegments()));
  }
  if (changed & view::kStatusChanged) {
    const view::StatusRow& row = model_.status.at(model_.newest_status);
    publish("/status/" + (row.process.empty() ? std::string("unnamed") : row.process), "adit.Status", statusJson(row));
  }
  if (changed & (view::kSubmapsAdded | view::kSubmapsMoved)) map_pending_ = true;
  if (trajectories_pending_ && due(log_utime, last_trajectory_utime_, options_.trajectory_period_s)) writeTrajectories(log_utime);
  if (map_pending_ && ((changed & view::kSubmapsMoved) || due(log_utime, last_map_utime_, options_.map_period_s)))
    writeMap(log_utime);
}

void FoxgloveRun::writeTrajectories(std::int64_t utime) {
  const double step = options_.trajectory_step_m;
  if (!model_.odometry.empty()) {
    publish("/trajectory/odometry", "foxglove.PosesInFrame",
            posesInFrameJson(utime, "world", view::thinTrajectory(model_.odometry, step)));
    publish("/trajectory/corrected", "foxglove.PosesInFrame",
            posesInFrameJson(utime, "world", view::thinTrajectory(model_.correctedTrajectory(), step)));
  }
  if (!model_.ground_truth.empty())
    publish("/trajectory/ground_truth", "foxglove.PosesInFrame",
            posesInFrameJson(utime, "world", view::thinTrajectory(model_.groundTruthInWorld(), step)));
  last_trajectory_utime_ = utime;
  trajectories_pending_ = false;
}

void FoxgloveRun::writeMap(std::int64_t utime) {
  publish("/map", "foxglove.PointCloud", pointCloudJson(utime, "world", model_.mapPoints(), nullptr));
  last_map_utime_ = utime;
  map_pending_ = false;
}

void FoxgloveRun::finish() {
  if (trajectories_pending_) writeTrajectories(log_utime_);
  if (map_pending_) writeMap(log_utime_);
}

}  // namespace adit::foxglove
