// MAP_UPDATE's submaps are named by keyframe number (seq), which stays when older keyframes are merged out of
// the loop closer's graph (loop.retire_after_keyframes): every submap is added once, a merged-out one is never
// named again, and a moved pose always names a keyframe still in the graph.
#include "loop/loop_closer.hpp"
#include "map/map_updates.hpp"

#include <gtest/gtest.h>

#include <set>

using namespace adit;

TEST(MapUpdates, SubmapsKeepTheirNumberWhenOlderKeyframesAreMergedOut) {
  LoopCloserConfig config;
  config.retire_after_keyframes = 60;  // keyframes without a cloud (these sweeps are empty) merge out
  config.retire_batch = 20;
  LoopCloser closer(config);
  MapUpdateConfig updates;
  updates.period_s = 0.5;
  MapUpdateTracker tracker(updates);
  std::set<int> added;
  for (int k = 0; k < 200; ++k) {
    PoseEstimate mapped;
    mapped.utime = static_cast<std::int64_t>(k) * 1000000;
    mapped.pose.translation().x() = k;  // one keyframe a sweep
    LidarScan empty;
    empty.utime = mapped.utime;
    closer.process(mapped, empty);
    const auto update = tracker.update(mapped.utime, closer);
    if (!update) continue;
    std::set<int> in_graph;
    for (const LoopCloser::Keyframe& kf : closer.keyframes()) in_graph.insert(static_cast<int>(kf.seq));
    for (const NewSubmap& s : update->added) {
      EXPECT_TRUE(added.insert(s.where.id).second) << "submap " << s.where.id << " added twice";
      EXPECT_EQ(s.where.utime, static_cast<std::int64_t>(s.where.id) * 1000000);
    }
    for (const SubmapPose& m : update->moved) EXPECT_TRUE(in_graph.count(m.id)) << m.id;
    EXPECT_EQ(update->num_submaps, static_cast<int>(closer.keyframes().size()));
  }
  EXPECT_EQ(added.size(), 200u) << "every keyframe was sent once";
  EXPECT_GE(closer.stats().retired_keyframes, 100);
  EXPECT_LE(closer.keyframes().size(), 60u + 20u + 1u);
}
