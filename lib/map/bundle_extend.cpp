#include "map/bundle_extend.hpp"

#include "loop/voxel_filter.hpp"
#include "mapping/voxel_key.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <optional>
#include <unordered_set>

namespace adit {

const ConfigTable<BundleExtendConfig>& bundleExtendConfigTable() {
  using E = BundleExtendConfig;
  static const ConfigTable<E> table = [] {
    ConfigTable<E> t("reloc.extend");
    t.add("overlap_radius", &E::overlap_radius, above(0), "m", "extend: a new keyframe this close to a saved one is roadway the map already holds (dropped)")
     .add("max_anchor_gap_s", &E::max_anchor_gap_s, above(0), "s", "extend: a measured pose in the map ties the keyframe nearest it in time when within this")
     .add("anchor_sigma_m", &E::anchor_sigma_m, above(0), "m", "extend: standard deviation of a measured pose in the map (translation)")
     .add("anchor_sigma_deg", &E::anchor_sigma_deg, above(0), "deg", "extend: standard deviation of a measured pose in the map (rotation)")
     .add("map_clearance_voxels", &E::map_clearance_voxels, between(0, 10), "voxels", "extend: a new map point is added only where no saved point lies within this many voxels")
     .add("hold_saved_map", &E::hold_saved_map, anyValue(), "", "extend: keep the saved map's keyframes and points where they are (else the graph of both runs is solved whole and the saved map redrawn)");
    return t;
  }();
  return table;
}

namespace {

// The element of `trajectory` (sorted by time) nearest `utime`, or nullptr when none is within `tolerance_us`.
const StampedPose* nearestInTime(const Trajectory& trajectory, std::int64_t utime, std::int64_t tolerance_us) {
  const auto after = std::lower_bound(trajectory.begin(), trajectory.end(), utime,
                                      [](const StampedPose& p, std::int64_t t) { return p.utime < t; });
  const StampedPose* best = nullptr;
  if (after != trajectory.end()) best = &*after;
  if (after != trajectory.begin() && (!best || utime - std::prev(after)->utime < best->utime - utime)) best = &*std::prev(after);
  return best && std::llabs(best->utime - utime) <= tolerance_us ? best : nullptr;
}

// Index of the keyframe nearest `utime` (keyframes are in time order).
int nearestKeyframeInTime(const std::vector<BundleKeyframe>& keyframes, std::int64_t utime) {
  const auto after = std::lower_bound(keyframes.begin(), keyframes.end(), utime,
                                      [](const BundleKeyframe& k, std::int64_t t) { return k.utime < t; });
  int best = after == keyframes.end() ? -1 : static_cast<int>(after - keyframes.begin());
  if (after != keyframes.begin() && (best < 0 || utime - std::prev(after)->utime < after->utime - utime))
    best = static_cast<int>(after - keyframes.begin()) - 1;
  return best;
}

// Index of the position nearest `position` and its distance.
std::pair<int, double> nearest(const std::vector<Eigen::Vector3d>& positions, const Eigen::Vector3d& position) {
  std::pair<int, double> best{-1, std::numeric_limits<double>::infinity()};
  for (std::size_t k = 0; k < positions.size(); ++k) {
    const double d = (positions[k] - position).norm();
    if (d < best.second) best = {static_cast<int>(k), d};
  }
  return best;
}

std::vector<Eigen::Vector3d> positionsOf(const std::vector<BundleKeyframe>& keyframes) {
  std::vector<Eigen::Vector3d> out;
  for (const BundleKeyframe& k : keyframes) out.push_back(k.pose.translation());
  return out;
}

Matrix6d anchorInformation(const BundleExtendConfig& c) {
  const double sigma_r = c.anchor_sigma_deg * M_PI / 180.0;
  Matrix6d information = Matrix6d::Zero();
  information.diagonal() << Eigen::Vector3d::Constant(1.0 / (c.anchor_sigma_m * c.anchor_sigma_m)),
      Eigen::Vector3d::Constant(1.0 / (sigma_r * sigma_r));
  return information;
}

// Voxels the saved map occupies: a new point near one of them would be a second copy of a mapped surface.
class Occupancy {
 public:
  explicit Occupancy(double cell) : cell_(cell) {}
  void add(const Eigen::Vector3f& p) { cells_.insert(voxelOf(p, cell_)); }
  bool near(const Eigen::Vector3f& p, int clearance) const {
    const VoxelKey k = voxelOf(p, cell_);
    for (int dx = -clearance; dx <= clearance; ++dx)
      for (int dy = -clearance; dy <= clearance; ++dy)
        for (int dz = -clearance; dz <= clearance; ++dz)
          if (cells_.count({k.x + dx, k.y + dy, k.z + dz})) return true;
    return false;
  }

 private:
  double cell_;
  std::unordered_set<VoxelKey, VoxelKeyHash> cells_;  // looked up only: its order never reaches the result
};

// Session keyframe -> its pose in the map frame, from the anchor nearest it in time (one per keyframe).
std::map<int, Eigen::Isometry3d> anchoredKeyframes(const MapBundle& session, const Trajectory& session_poses,
                                                   const Trajectory& anchors, const BundleExtendConfig& config) {
  std::map<int, std::pair<std::int64_t, Eigen::Isometry3d>> best;  // keyframe -> (time gap, pose in map)
  const auto max_gap = static_cast<std::int64_t>(config.max_anchor_gap_s * 1e6);
  for (const StampedPose& anchor : anchors) {
    const StampedPose* sweep = nearestInTime(session_poses, anchor.utime, 1000);  // the same sweep (TUM: 1 us)
    const int k = nearestKeyframeInTime(session.keyframes, anchor.utime);
    if (!sweep || k < 0 || !anchor.pose.matrix().allFinite()) continue;
    const std::int64_t gap = std::llabs(session.keyframes[static_cast<std::size_t>(k)].utime - anchor.utime);
    if (gap > max_gap || (best.count(k) && best[k].first <= gap)) continue;
    // The keyframe is a few centimetres of session motion from the anchored sweep: carry the anchor over it.
    best[k] = {gap, anchor.pose * sweep->pose.inverse() * session.keyframes[static_cast<std::size_t>(k)].pose};
  }
  std::map<int, Eigen::Isometry3d> out;
  for (const auto& [k, v] : best) out[k] = v.second;
  return out;
}

// The pose graph of both runs, solved: the saved map's nodes 0..N-1 (held only with hold_saved_map; else only
// node 0, the map's frame), then the session's, started from the offset to the map of the anchor nearest in time,
// joined by the session's own edges and one edge per anchor from the nearest saved keyframe.
struct JointGraph {
  PoseGraph graph;
  std::vector<PoseGraphEdge> anchor_edges;
};

JointGraph solveJointGraph(const MapBundle& prior, const MapBundle& session, const std::map<int, Eigen::Isometry3d>& anchored,
                           const BundleExtendConfig& config, BundleExtendReport& report) {
  const int N = static_cast<int>(prior.keyframes.size());
  JointGraph joint{prior.graph, {}};
  std::vector<std::pair<std::int64_t, Eigen::Isometry3d>> offsets;  // T_map_session at anchored keyframes
  for (const auto& [k, T_map_kf] : anchored)
    offsets.emplace_back(session.keyframes[static_cast<std::size_t>(k)].utime,
                         T_map_kf * session.keyframes[static_cast<std::size_t>(k)].pose.inverse());
  for (const BundleKeyframe& k : session.keyframes) {
    const auto nearest = std::min_element(offsets.begin(), offsets.end(), [&](const auto& a, const auto& b) {
      return std::llabs(a.first - k.utime) < std::llabs(b.first - k.utime);
    });
    joint.graph.addNode(nearest->second * k.pose);
  }
  for (PoseGraphEdge e : session.graph.edges()) {
    e.from += N;
    e.to += N;
    joint.graph.addEdge(e);
  }
  const std::vector<Eigen::Vector3d> measured_against = positionsOf(prior.keyframes);
  for (const auto& [k, T_map_kf] : anchored) {
    const int j = nearest(measured_against, T_map_kf.translation()).first;
    joint.anchor_edges.push_back({j, N + k, prior.keyframes[static_cast<std::size_t>(j)].pose.inverse() * T_map_kf,
                                  anchorInformation(config), true});
    joint.graph.addEdge(joint.anchor_edges.back());
  }
  PoseGraphConfig solve;
  solve.fixed_nodes = config.hold_saved_map ? N : 1;
  solve.max_iterations = 100;
  report.solved = joint.graph.optimize(solve).solved;
  if (!report.solved) throw BundleError("the pose graph joining the new session to the saved map did not solve");
  return joint;
}

// The saved keyframes at their solved poses, then the session's except those on mapped roadway (within
// overlap_radius of a saved one), into `out` with their graph: the saved edges, the session's and the anchors'
// between kept nodes, and where a kept stretch's neighbour was dropped an edge to the nearest saved keyframe at
// the solved relative pose (the graph stays connected). Returns each session keyframe's node in `out` (-1: dropped).
std::vector<int> joinKeyframes(const MapBundle& prior, const MapBundle& session, const JointGraph& joint,
                               const BundleExtendConfig& config, MapBundle& out, BundleExtendReport& report) {
  const int N = static_cast<int>(prior.keyframes.size()), M = static_cast<int>(session.keyframes.size());
  out.keyframes = prior.keyframes;
  for (int i = 0; i < N; ++i) {
    BundleKeyframe& k = out.keyframes[static_cast<std::size_t>(i)];
    report.saved_moved_max_m = std::max(report.saved_moved_max_m, (joint.graph.pose(i).translation() - k.pose.translation()).norm());
    k.pose = joint.graph.pose(i);
    out.graph.addNode(k.pose);
  }
  for (const PoseGraphEdge& e : prior.graph.edges()) out.graph.addEdge(e);
  const std::vector<Eigen::Vector3d> saved = positionsOf(out.keyframes);
  std::vector<int> id(static_cast<std::size_t>(M), -1);
  for (int i = 0; i < M; ++i) {
    const Eigen::Isometry3d& pose = joint.graph.pose(N + i);
    if (nearest(saved, pose.translation()).second < config.overlap_radius) {
      ++report.overlap_keyframes;
      continue;
    }
    const BundleKeyframe& k = session.keyframes[static_cast<std::size_t>(i)];
    id[static_cast<std::size_t>(i)] = out.graph.addNode(pose);
    out.keyframes.push_back({k.utime, pose, k.cloud, k.context});
  }
  report.kept_keyframes = M - report.overlap_keyframes;
  const auto kept = [&](int i) { return i >= 0 && i < M && id[static_cast<std::size_t>(i)] >= 0; };
  for (PoseGraphEdge e : session.graph.edges()) {
    if (!kept(e.from) || !kept(e.to)) continue;
    e.from = id[static_cast<std::size_t>(e.from)];
    e.to = id[static_cast<std::size_t>(e.to)];
    out.graph.addEdge(e);
  }
  for (PoseGraphEdge e : joint.anchor_edges) {
    if (!kept(e.to - N)) continue;
    e.to = id[static_cast<std::size_t>(e.to - N)];
    out.graph.addEdge(e);
  }
  for (int i = 0; i < M; ++i) {
    if (!kept(i) || ((i == 0 || kept(i - 1)) && (i == M - 1 || kept(i + 1)))) continue;
    const Eigen::Isometry3d& pose = joint.graph.pose(N + i);
    const int j = nearest(saved, pose.translation()).first;
    out.graph.addOdometryEdge(j, id[static_cast<std::size_t>(i)], joint.graph.pose(j).inverse() * pose, anchorInformation(config));
    ++report.junction_edges;
  }
  return id;
}

// The saved map (as it was with hold_saved_map, else redrawn from the saved keyframes at their solved poses the
// way the loop closer draws a map), and the kept session keyframes' points where it has none nearby.
std::vector<Eigen::Vector3f> joinedMap(const MapBundle& prior, const MapBundle& out, const MapBundle& session,
                                       const PoseGraph& solved, const std::vector<int>& id,
                                       const BundleExtendConfig& config, BundleExtendReport& report) {
  const double voxel = prior.summary.map_voxel;
  const int N = static_cast<int>(prior.keyframes.size());
  Occupancy occupied(voxel > 0 ? voxel : 0.1);
  std::vector<Eigen::Vector3f> points;
  std::optional<VoxelAccumulator> grid;  // map_voxel 0: the points as they are
  if (voxel > 0) grid.emplace(voxel);
  const auto add = [&](const Eigen::Vector3f& p) { grid ? grid->add(p) : points.push_back(p); };
  const auto addCloud = [&](const BundleKeyframe& k, const Eigen::Isometry3d& pose, bool saved) {
    const Eigen::Isometry3f T = pose.cast<float>();
    for (const Eigen::Vector3f& p : k.cloud.decode()) {
      const Eigen::Vector3f w = T * p;
      if (!w.allFinite() || (!saved && occupied.near(w, config.map_clearance_voxels))) continue;
      if (saved) occupied.add(w);
      else ++report.map_points_added;
      add(w);
    }
  };
  if (config.hold_saved_map) {
    for (const Eigen::Vector3f& p : prior.map) occupied.add(p), add(p);
  } else {
    for (int i = 0; i < N; ++i) addCloud(out.keyframes[static_cast<std::size_t>(i)], out.keyframes[static_cast<std::size_t>(i)].pose, true);
  }
  for (std::size_t i = 0; i < id.size(); ++i)
    if (id[i] >= 0) addCloud(session.keyframes[i], solved.pose(N + static_cast<int>(i)), false);
  return grid ? grid->centroids() : points;
}

}  // namespace

MapBundle extendBundle(const MapBundle& prior, const MapBundle& session, const Trajectory& session_poses,
                       const Trajectory& anchors, const BundleExtendConfig& config, BundleExtendReport* report_out) {
  BundleExtendReport report;
  const int N = static_cast<int>(prior.keyframes.size());
  const int M = static_cast<int>(session.keyframes.size());
  if (N == 0 || prior.graph.size() != N) throw BundleError("the saved map has no keyframes or a pose graph of another size");
  if (M == 0 || session.graph.size() != M) throw BundleError("the new session has no keyframes to add");
  if (const std::string mismatch = bundleSensorMismatch(prior.summary, session.config); !mismatch.empty())
    throw BundleError("the new session's sensor configuration differs from the saved map's: " + mismatch);
  const std::map<int, Eigen::Isometry3d> anchored = anchoredKeyframes(session, session_poses, anchors, config);
  report.anchors = static_cast<int>(anchors.size());
  report.anchors_used = static_cast<int>(anchored.size());
  report.session_keyframes = M;
  if (anchored.empty())
    throw BundleError(fmt::format("the new session never relocalised in the saved map ({} measured poses, none within "
                                  "{} s of a keyframe): nothing ties it to the map",
                                  anchors.size(), config.max_anchor_gap_s));

  const JointGraph joint = solveJointGraph(prior, session, anchored, config, report);
  MapBundle out;
  const std::vector<int> id = joinKeyframes(prior, session, joint, config, out, report);
  out.map = joinedMap(prior, out, session, joint.graph, id, config, report);
  out.config = session.config;
  std::vector<Eigen::Vector3d> session_positions;
  for (int i = 0; i < M; ++i) session_positions.push_back(joint.graph.pose(N + i).translation());
  std::vector<Eigen::Vector3d> saved = positionsOf(out.keyframes);
  saved.resize(static_cast<std::size_t>(N));
  report.added_roadway_m = roadwayLength(session_positions, 3.0, 30, saved);
  out.summary = bundleSummaryOf(out.keyframes, prior.summary.map_voxel, out.config,
                                prior.summary.roadway_length_m + report.added_roadway_m);
  if (report_out) *report_out = report;
  return out;
}

}  // namespace adit
