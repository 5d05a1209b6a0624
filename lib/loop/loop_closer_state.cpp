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
          &s.optimizations, &s.retired_keyframes};
}

// Leads the state: a checkpoint of the format before keyframes could be merged out (which began with the
// keyframe count) is refused rather than misread.
constexpr std::uint64_t kStateFormat = 0xAD17'0002'0000'0000ULL;
constexpr std::size_t kRetiredBytes = 8 + 8 + 7 * 4;

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
  w.put<std::uint64_t>(kStateFormat);
  // Records the keyframe log holds: one per keyframe ever made (seq order), merged out or not.
  w.put<std::uint64_t>(static_cast<std::uint64_t>(stats_.keyframes));
  // The keyframes in the graph: number, graph pose and chain step (a merged step is not the record's).
  w.put<std::uint64_t>(keyframes_.size());
  for (int k = 0; k < graph_.size(); ++k) {
    w.put<std::int64_t>(keyframes_[static_cast<std::size_t>(k)].seq);
    w.putPose(graph_.pose(k));
    w.putMatrix(chain_.stepCovariance(k));
  }
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
  w.put<std::uint64_t>(retired_.size());
  for (const RetiredKeyframe& x : retired_) {
    w.put<std::int64_t>(x.utime);
    w.put<std::int64_t>(x.anchor_seq);
    for (float v : x.translation) w.put<float>(v);
    for (float v : x.rotation) w.put<float>(v);
  }
  return w.bytes();
}

std::size_t LoopCloser::keyframesInState(const std::string& state) {
  ByteReader r(state);
  const auto format = r.get<std::uint64_t>();
  const auto records = r.get<std::uint64_t>();
  return r.ok() && format == kStateFormat && records < (1ULL << 31) ? static_cast<std::size_t>(records) : 0;
}

bool LoopCloser::restoreState(const std::string& state, const std::vector<std::string>& keyframe_records) {
  ByteReader r(state);
  LoopCloser restored(config_);
  const std::size_t records = keyframesInState(state);
  r.get<std::uint64_t>();
  r.get<std::uint64_t>();
  const auto n = r.getCount(8 + 96 + 288);  // seq, graph pose and step per keyframe
  if (!r.ok() || keyframe_records.size() < records || n > records) return false;
  std::int64_t previous_seq = -1;
  for (std::uint64_t k = 0; k < n && r.ok(); ++k) {
    const std::int64_t seq = r.get<std::int64_t>();
    const Eigen::Isometry3d pose = r.getPose();
    const Matrix6d step = r.getMatrix<Matrix6d>();
    if (!r.ok() || seq <= previous_seq || seq >= static_cast<std::int64_t>(records)) return false;
    previous_seq = seq;
    ByteReader kr(keyframe_records[static_cast<std::size_t>(seq)]);
    Keyframe kf;
    kf.seq = seq;
    kf.utime = kr.get<std::int64_t>();
    kf.uncorrected = kr.getPose();
    std::optional<CompactCloud> cloud = getCompactCloud(kr);
    std::optional<ScanContext> context = cloud ? getScanContext(kr) : std::nullopt;
    if (!context) return false;
    kr.getMatrix<Matrix6d>();  // the step as first made; the state's is the graph's now
    std::optional<KeyframeKeypoints> keypoints = KeyframeKeypoints();
    if (kr.ok() && !kr.atEnd()) keypoints = KeyframeKeypoints::get(kr);
    if (!kr.ok() || !kr.atEnd() || !keypoints) return false;
    restored.chain_.add(kf.uncorrected, step);
    restored.graph_.addNode(pose);
    restored.database_.add(*context, kf.utime);
    restored.keyframes_.push_back(std::move(kf));
    restored.clouds_.add(std::move(*cloud), keypoints->empty() ? nullptr
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
  const auto retired = r.getCount(kRetiredBytes);
  for (std::uint64_t i = 0; i < retired && r.ok(); ++i) {
    RetiredKeyframe x;
    x.utime = r.get<std::int64_t>();
    x.anchor_seq = r.get<std::int64_t>();
    for (float& v : x.translation) v = r.get<float>();
    for (float& v : x.rotation) v = r.get<float>();
    if (restored.indexOfKeyframe(x.anchor_seq) < 0) r.fail();  // rides on a keyframe the graph must hold
    restored.retired_.push_back(x);
  }
  if (!r.ok() || !r.atEnd() || restored.stats_.keyframes != static_cast<int>(records)) return false;
  // Not a saved field: a revisit keyframe is one without a cloud (those merged out counted as revisits).
  restored.stats_.revisit_keyframes = static_cast<int>(restored.retired_.size());
  for (int k = 0; k < static_cast<int>(restored.clouds_.size()); ++k)
    restored.stats_.revisit_keyframes += restored.clouds_.empty(k) ? 1 : 0;
  restored.stats_.partial_loops =
      static_cast<int>(std::count_if(restored.accepted_.begin(), restored.accepted_.end(), isPartialLoop));
  *this = std::move(restored);
  return true;
}

}  // namespace adit
