#include "map/map_updates.hpp"

#include "core/geometry.hpp"
#include "loop/voxel_filter.hpp"

#include <algorithm>

namespace adit {

const ConfigTable<MapUpdateConfig>& mapUpdateConfigTable() {
  using M = MapUpdateConfig;
  static const ConfigTable<M> table = [] {
    ConfigTable<M> t("map");
    t.add("update_period_s", &M::period_s, above(0), "s", "least sensor time between two MAP_UPDATE messages")
     .add("update_voxel_m", &M::voxel_m, aboveUpTo(0, 100), "m", "decimation of a submap's points for viewers")
     .add("update_move_m", &M::move_threshold_m, atLeast(0), "m", "a submap moved less than this (and the angle) is not resent")
     .add("update_move_deg", &M::move_threshold_deg, atLeast(0), "deg", "a submap turned less than this (and the distance) is not resent")
     .add("update_max_points", &M::max_points, between(1, 10000000), "", "points per update; more new submaps wait for the next")
     .add("update_max_moved", &M::max_moved, between(1, 10000000), "", "moved poses per update; more wait for the next");
    return t;
  }();
  return table;
}

MapUpdateConfig mapUpdateConfigFrom(const Config& c) { return mapUpdateConfigTable().read(c); }

std::optional<MapUpdate> MapUpdateTracker::update(std::int64_t utime, const LoopCloser& closer) {
  if (last_utime_ >= 0 && utime - last_utime_ < toUtime(config_.period_s)) return std::nullopt;
  const auto& keyframes = closer.keyframes();
  const PoseGraph& graph = closer.graph();
  MapUpdate out;
  out.utime = utime;
  out.num_submaps = static_cast<int>(keyframes.size());
  out.num_loops = static_cast<int>(closer.acceptedLoops().size());
  const double max_angle = config_.move_threshold_deg * 3.14159265358979323846 / 180.0;
  // Sent submaps and the keyframes are both in seq order: walk them together.
  std::size_t k = 0, kept = 0;
  for (Sent& sent : sent_) {
    while (k < keyframes.size() && keyframes[k].seq < sent.seq) ++k;
    if (k == keyframes.size() || keyframes[k].seq != sent.seq) continue;  // merged out: never moves again
    const Eigen::Isometry3d& now = graph.pose(static_cast<int>(k));
    const Eigen::Isometry3d delta = sent.pose.inverse() * now;
    const bool moved = translationNorm(delta) >= config_.move_threshold_m || rotationAngle(delta) >= max_angle;
    if (moved && static_cast<int>(out.moved.size()) < config_.max_moved) {
      out.moved.push_back({static_cast<int>(sent.seq), keyframes[k].utime, now});
      sent.pose = now;
    }
    sent_[kept++] = sent;
  }
  sent_.resize(kept);
  std::size_t points = 0;
  const auto unsent = std::lower_bound(keyframes.begin(), keyframes.end(), next_seq_,
                                       [](const LoopCloser::Keyframe& kf, std::int64_t seq) { return kf.seq < seq; });
  for (k = static_cast<std::size_t>(unsent - keyframes.begin()); k < keyframes.size(); ++k) {
    std::vector<Eigen::Vector3f> decimated = voxelDownsample(closer.keyframeCloud(static_cast<int>(k)).decode(), config_.voxel_m);
    // Always at least one submap per update, so a huge one cannot stall the stream.
    if (!out.added.empty() && points + decimated.size() > static_cast<std::size_t>(config_.max_points)) break;
    points += decimated.size();
    const Eigen::Isometry3d pose = graph.pose(static_cast<int>(k));
    out.added.push_back({{static_cast<int>(keyframes[k].seq), keyframes[k].utime, pose}, std::move(decimated)});
    sent_.push_back({keyframes[k].seq, pose});
    next_seq_ = keyframes[k].seq + 1;
  }
  if (out.added.empty() && out.moved.empty()) return std::nullopt;
  last_utime_ = utime;
  return out;
}

}  // namespace adit
