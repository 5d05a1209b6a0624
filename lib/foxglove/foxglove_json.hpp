// adit's run data as Foxglove messages in JSON (the message encoding "json" of MCAP and of the Foxglove
// WebSocket protocol): the field names and layouts of foxglove_schemas.hpp. Times are sensor time in
// microseconds (negative clamps to 0); byte fields (a point cloud's data) are base64.
#pragma once

#include "view/run_model.hpp"

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace adit::foxglove {

// Points as x, y, z float32 (and intensity float32 when given, one per point): stride 12 or 16 bytes.
std::string pointCloudJson(std::int64_t utime, const std::string& frame_id, const std::vector<Eigen::Vector3f>& points,
                           const std::vector<float>* intensity);
std::string frameTransformJson(std::int64_t utime, const std::string& parent, const std::string& child,
                               const Eigen::Isometry3d& pose);
std::string posesInFrameJson(std::int64_t utime, const std::string& frame_id, const std::vector<view::TimedPose>& poses);
// One scene entity `id` with a LINE_LIST of the segments (thickness in pixels), replacing the previous one.
std::string lineListSceneJson(std::int64_t utime, const std::string& frame_id, const std::string& id,
                              const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments);
std::string statusJson(const view::StatusRow& row);

}  // namespace adit::foxglove
