// LoopCloser state <-> bytes, for checkpoints: everything process() depends on, so a restored loop closer
// continues exactly as the one that wrote the checkpoint would have (same keyframes, graph, pending loops).
#include "core/byte_codec.hpp"
#include "loop/keyframe_codec.hpp"
#include "loop/loop_closer.hpp"

#include <algorithm>

namespace adit {
namespace {

void putLoop(ByteWriter& w, const LoopConstraint& l) {
  w.put<std::int32_t>(l.query_index);
  w.put<std::int32_t>(l.match_index);
  w.put<std::int64_t>(l.query_utime);
  w.put<std::int64_t>(l.match_utime);
  w.putPose(l.T_match_query);
  w.putMatrix(l.information);
  for (double v : {l.scan_context_distance, l.scan_context_yaw, l.fitness, l.inlier_ratio}) w.put<double>(v);
}

LoopConstraint getLoop(ByteReader& r) {
  LoopConstraint l;
  l.query_index = r.get<std::int32_t>();
  l.match_index = r.get<std::int32_t>();
  l.query_utime = r.get<std::int64_t>();
  l.match_utime = r.get<std::int64_t>();
  l.T_match_query = r.getPose();
  l.information = r.getMatrix<Matrix6d>();
  l.scan_context_distance = r.get<double>();
  l.scan_context_yaw = r.get<double>();
  l.fitness = r.get<double>();
  l.inlier_ratio = r.get<double>();
  return l;
}

constexpr std::size_t kLoopBytes = 4 + 4 + 8 + 8 + 96 + 288 + 32;

void putLoops(ByteWriter& w, const std::vector<LoopConstraint>& loops) {
  w.put<std::uint64_t>(loops.size());
  for (const LoopConstraint& l : loops) putLoop(w, l);
}

std::vector<LoopConstraint> getLoops(ByteReader& r, int keyframes) {
  std::vector<LoopConstraint> loops(r.getCount(kLoopBytes));
  for (LoopConstraint& l : loops) {
    l = getLoop(r);
    if (l.query_index < 0 || l.query_index >= keyframes || l.match_index < 0 || l.match_index >= keyframes) r.fail();
  }
  return loops;
}

// Every counter of LoopCloserStats, in declaration order.
std::vector<int*> statFields(LoopCloserStats& s) {
  return {&s.sweeps, &s.invalid_sweeps, &s.keyframes, &s.queries, &s.candidates, &s.rejected_fitness,
          &s.rejected_degenerate, &s.rejected_odometry, &s.rejected_pairwise, &s.pending, &s.accepted,
          &s.optimizations};
}

}  // namespace

std::string LoopCloser::keyframeRecord(int k) const {
  ByteWriter w;
  const Keyframe& kf = keyframes_[static_cast<std::size_t>(k)];
  w.put<std::int64_t>(kf.utime);
  w.putPose(kf.uncorrected);
  putCompactCloud(w, clouds_.cloud(k));
  putScanContext(w, database_.context(k));
  w.putMatrix(chain_.stepCovariance(k));
  keyframeKeypoints(k).put(w);  // last: records written before it have none
  return w.bytes();
}

std::string LoopCloser::saveState() const {
  ByteWriter w;
  w.put<std::uint64_t>(keyframes_.size());
  for (int k = 0; k < graph_.size(); ++k) w.putPose(graph_.pose(k));
  w.put<std::uint64_t>(graph_.edges().size());
  for (const PoseGraphEdge& e : graph_.edges()) {
    w.put<std::int32_t>(e.from);
    w.put<std::int32_t>(e.to);
    w.putPose(e.T_from_to);
    w.putMatrix(e.information);
    w.put<std::uint8_t>(e.robust ? 1 : 0);
  }
  putLoops(w, accepted_);
  putLoops(w, pending_);
  w.put<std::uint64_t>(sweeps_since_keyframe_.size());
  for (const auto& [pose, covariance] : sweeps_since_keyframe_) {
    w.putPose(pose);
    w.putMatrix(covariance);
  }
  w.put<std::int32_t>(last_loop_query_);
  LoopCloserStats stats = stats_;
  for (int* field : statFields(stats)) w.put<std::int32_t>(*field);
  return w.bytes();
}

std::size_t LoopCloser::keyframesInState(const std::string& state) {
  ByteReader r(state);
  const auto n = r.getCount(96);
  return r.ok() ? n : 0;
}

bool LoopCloser::restoreState(const std::string& state, const std::vector<std::string>& keyframe_records) {
  ByteReader r(state);
  LoopCloser restored(config_);
  const auto n = r.getCount(96);  // a graph pose per keyframe
  if (!r.ok() || keyframe_records.size() < n) return false;
  for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
    const std::string& record = keyframe_records[k];
    ByteReader kr(record);
    Keyframe kf;
    kf.utime = kr.get<std::int64_t>();
    kf.uncorrected = kr.getPose();
    std::optional<CompactCloud> cloud = getCompactCloud(kr);
    std::optional<ScanContext> context = cloud ? getScanContext(kr) : std::nullopt;
    if (!context) return false;
    const Matrix6d step = kr.getMatrix<Matrix6d>();
    std::optional<KeyframeKeypoints> keypoints = KeyframeKeypoints();
    if (kr.ok() && !kr.atEnd()) keypoints = KeyframeKeypoints::get(kr);
    if (!kr.ok() || !kr.atEnd() || !keypoints) return false;
    restored.chain_.add(kf.uncorrected, step);
    restored.graph_.addNode(r.getPose());
    restored.database_.add(*context, kf.utime);
    restored.keyframes_.push_back(std::move(kf));
    restored.clouds_.add(std::move(*cloud));
    restored.keypoints_.push_back(keypoints->empty() ? nullptr
                                                     : std::make_shared<const KeyframeKeypoints>(std::move(*keypoints)));
  }
  const auto edges = r.getCount(4 + 4 + 96 + 288 + 1);
  for (std::uint64_t i = 0; i < edges && r.ok(); ++i) {
    PoseGraphEdge e;
    e.from = r.get<std::int32_t>();
    e.to = r.get<std::int32_t>();
    e.T_from_to = r.getPose();
    e.information = r.getMatrix<Matrix6d>();
    e.robust = r.get<std::uint8_t>() != 0;
    if (r.ok() && !restored.graph_.addEdge(e)) r.fail();
  }
  const int keyframes = static_cast<int>(restored.keyframes_.size());
  restored.accepted_ = getLoops(r, keyframes);
  restored.pending_ = getLoops(r, keyframes);
  const auto sweeps = r.getCount(96 + 288);
  for (std::uint64_t i = 0; i < sweeps && r.ok(); ++i) {
    const Eigen::Isometry3d pose = r.getPose();
    restored.sweeps_since_keyframe_.emplace_back(pose, r.getMatrix<Matrix6d>());
  }
  restored.last_loop_query_ = r.get<std::int32_t>();
  for (int* field : statFields(restored.stats_)) *field = r.get<std::int32_t>();
  if (!r.ok() || !r.atEnd()) return false;
  // Not a saved field (older checkpoints lack it): a revisit keyframe is the one record without a cloud.
  restored.stats_.revisit_keyframes = 0;
  for (int k = 0; k < static_cast<int>(restored.clouds_.size()); ++k)
    restored.stats_.revisit_keyframes += restored.clouds_.empty(k) ? 1 : 0;
  restored.stats_.partial_loops =
      static_cast<int>(std::count_if(restored.accepted_.begin(), restored.accepted_.end(), isPartialLoop));
  *this = std::move(restored);
  return true;
}

}  // namespace adit
