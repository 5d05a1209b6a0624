// Revisit keyframes merged out of the graph (loop.retire_after_keyframes; the graph side in loop/graph_merge.hpp).
#include "loop/graph_merge.hpp"
#include "loop/keep_mask.hpp"
#include "loop/loop_closer.hpp"
#include "loop/loop_job.hpp"

#include <algorithm>
#include <map>

namespace adit {
namespace {

// Loops whose two keyframes stay, renumbered; a loop whose query was merged out goes with it.
void renumber(std::vector<LoopConstraint>& loops, const std::vector<int>& new_index) {
  std::vector<LoopConstraint> kept;
  for (LoopConstraint loop : loops) {
    const int q = new_index[static_cast<std::size_t>(loop.query_index)];
    const int m = new_index[static_cast<std::size_t>(loop.match_index)];
    if (q < 0 || m < 0) continue;
    loop.query_index = q;
    loop.match_index = m;
    kept.push_back(loop);
  }
  loops = std::move(kept);
}

}  // namespace

Eigen::Isometry3d LoopCloser::RetiredKeyframe::offset() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(rotation[3], rotation[0], rotation[1], rotation[2]).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(translation[0], translation[1], translation[2]);
  return T;
}

void LoopCloser::RetiredKeyframe::setOffset(const Eigen::Isometry3d& offset) {
  const Eigen::Quaterniond q(offset.linear());
  const double xyzw[4] = {q.x(), q.y(), q.z(), q.w()};
  for (int i = 0; i < 3; ++i) translation[i] = static_cast<float>(offset.translation()[i]);
  for (int i = 0; i < 4; ++i) rotation[i] = static_cast<float>(xyzw[i]);
}

// Keyframes without a cloud that are older than the newest retire_after_keyframes (and not held back by
// keepKeyframesFrom) are merged out once there are retire_batch of them. The loop jobs in flight are applied
// first (their snapshots name keyframes by index): a fixed point of the input, so replay stays deterministic;
// the sweep waits for the worker there, once per batch.
void LoopCloser::retireRevisits(Result& result) {
  if (config_.retire_after_keyframes <= 0) return;
  // Never within the windows that count keyframes (loop search exclusion, consistency, revisit trust).
  const int window = std::max({config_.exclude_recent_keyframes, config_.consistency_window, config_.revisit_trust_keyframes});
  const int n = static_cast<int>(keyframes_.size());
  const int older_than = n - std::max(config_.retire_after_keyframes, window + 1);
  if (older_than <= 1) return;
  const auto retirable = [&](int k) { return clouds_.empty(k) && keyframes_[static_cast<std::size_t>(k)].seq < keep_from_seq_; };
  int count = 0;
  for (int k = 1; k < older_than; ++k) count += retirable(k) ? 1 : 0;
  if (count < config_.retire_batch) return;

  applyDue(0, true, result);
  std::vector<bool> is_match(static_cast<std::size_t>(n), false);  // never for a keyframe without a cloud: checked anyway
  for (const std::vector<LoopConstraint>* loops : {&accepted_, &pending_})
    for (const LoopConstraint& loop : *loops) is_match[static_cast<std::size_t>(loop.match_index)] = true;
  std::vector<bool> keep(static_cast<std::size_t>(n), true);
  for (int k = 1; k < older_than; ++k)
    if (retirable(k) && !is_match[static_cast<std::size_t>(k)]) keep[static_cast<std::size_t>(k)] = false;

  // Each merged keyframe rides on the nearest older keyframe that stays; those riding on a keyframe merged
  // out now move onto its anchor.
  std::map<std::int64_t, std::pair<std::int64_t, Eigen::Isometry3d>> reanchor;  // seq -> anchor seq, offset
  int anchor = 0;
  std::vector<RetiredKeyframe> now;
  for (int k = 1; k < older_than; ++k) {
    if (keep[static_cast<std::size_t>(k)]) {
      anchor = k;
      continue;
    }
    const Keyframe& kf = keyframes_[static_cast<std::size_t>(k)];
    const Eigen::Isometry3d offset = correction(anchor).inverse() * correction(k);
    RetiredKeyframe r;
    r.utime = kf.utime;
    r.anchor_seq = keyframes_[static_cast<std::size_t>(anchor)].seq;
    r.setOffset(offset);
    now.push_back(r);
    reanchor[kf.seq] = {r.anchor_seq, offset};
    ++stats_.retired_keyframes;
  }
  for (RetiredKeyframe& r : retired_) {
    const auto it = reanchor.find(r.anchor_seq);
    if (it == reanchor.end()) continue;
    r.anchor_seq = it->second.first;
    r.setOffset(it->second.second * r.offset());
  }
  retired_.insert(retired_.end(), now.begin(), now.end());
  std::stable_sort(retired_.begin(), retired_.end(),
                   [](const RetiredKeyframe& a, const RetiredKeyframe& b) { return a.utime < b.utime; });

  MergedGraph merged = mergeOutNodes(graph_, chain_, keep);
  graph_ = std::move(merged.graph);
  chain_ = std::move(merged.chain);
  eraseUnkept(keyframes_, keep);
  clouds_.retain(keep);
  database_.retain(keep);
  renumber(accepted_, merged.new_index);
  renumber(pending_, merged.new_index);
  renumber(result.loops, merged.new_index);
  result.loop = result.loops.empty() ? std::nullopt : std::optional<LoopConstraint>(result.loops.back());
  if (last_loop_query_ >= 0) {  // the cooldown counts from the nearest kept keyframe at or before it
    int q = last_loop_query_;
    while (q > 0 && merged.new_index[static_cast<std::size_t>(q)] < 0) --q;
    last_loop_query_ = merged.new_index[static_cast<std::size_t>(q)];
  }
  if (scheduler_) scheduler_->replaceBook(LoopBook{accepted_, pending_, last_loop_query_});
}

}  // namespace adit
