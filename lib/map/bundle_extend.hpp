// Extending a saved map with a later session (issue 18, mode `extend`): the session relocalised in the map
// bundle, drove on into roadway the map does not hold, and is saved as one bundle of both sessions.
//
// What ties the session to the map are its anchors: the sweeps whose pose in the map frame the relocaliser
// measured (the fix, and every verified tracking fit), not carried by odometry. Each anchor becomes an edge
// from the nearest saved keyframe to the session keyframe nearest it in time; the session's own pose graph
// (odometry and its loops) joins its keyframes; with the saved graph this is one pose graph of both sessions.
// By default it is solved whole (only the map's first keyframe, its frame, held): a session that leaves the
// map and comes back into it elsewhere closes a loop through both, which corrects the saved map's own drift
// too, and the saved map is redrawn from its keyframes' clouds at their new poses. With hold_saved_map the
// saved keyframes and points stay exactly where they were (coordinates marked in the old map stay valid) and
// only the session's keyframes move. Where the session drove through mapped roadway its keyframes are dropped
// (the map already holds that roadway: no second copy of it, no ghost walls); the rest are added, with their
// clouds added to the map only where the saved map has no point nearby.
#pragma once

#include "core/config_table.hpp"
#include "core/types.hpp"
#include "map/map_bundle.hpp"

#include <string>
#include <vector>

namespace adit {

struct BundleExtendConfig {
  // A session keyframe this close (m) to a saved keyframe is roadway the map already holds: dropped.
  double overlap_radius = 2.0;
  // An anchor is used for the session keyframe nearest it in time when it is within this much sensor time.
  double max_anchor_gap_s = 0.5;
  // Standard deviations of an anchor (the relocaliser's ICP fit against the saved map).
  double anchor_sigma_m = 0.05;
  double anchor_sigma_deg = 0.5;
  // A new point is added to the map only when no saved map point lies within this many voxels of it.
  int map_clearance_voxels = 1;
  // Keep the saved map's keyframes and points where they are (only the session moves); else the graph of both
  // sessions is solved whole and the saved map redrawn.
  bool hold_saved_map = false;
};

const ConfigTable<BundleExtendConfig>& bundleExtendConfigTable();

struct BundleExtendReport {
  int anchors = 0;             // anchors given
  int anchors_used = 0;        // ... that became an edge (one per session keyframe at most)
  int session_keyframes = 0;
  int kept_keyframes = 0;      // added to the bundle
  int overlap_keyframes = 0;   // dropped: roadway the map already held
  int junction_edges = 0;      // edges joining a kept stretch to the saved map where its neighbour was dropped
  double saved_moved_max_m = 0.0;  // largest move of a saved keyframe (0 with hold_saved_map)
  std::size_t map_points_added = 0;
  double added_roadway_m = 0.0;
  bool solved = false;
};

// The bundle of both sessions. `prior` is the saved bundle (its map points, loadBundleMap, are read only with
// hold_saved_map); `session` the session's own bundle (bundleFrom of its loop closer: keyframes at corrected
// poses in the session's frame, its graph); `session_poses` the session's corrected pose of every sweep in the
// same frame (LoopCloser::correctedTrajectory) and `anchors` its measured poses in the map frame (POSE_IN_MAP
// flagged FLAG_MAP_MEASURED). Throws BundleError when no anchor ties the session to the map (it never
// relocalised) or the sessions' sensor keys differ.
MapBundle extendBundle(const MapBundle& prior, const MapBundle& session, const Trajectory& session_poses,
                       const Trajectory& anchors, const BundleExtendConfig& config, BundleExtendReport* report = nullptr);

}  // namespace adit
