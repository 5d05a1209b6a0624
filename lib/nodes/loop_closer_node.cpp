#include "nodes/loop_closer_node.hpp"

#include "core/byte_codec.hpp"
#include "core/geometry.hpp"
#include "loop/loop_closer.hpp"
#include "loop/pose_graph.hpp"
#include "map/bundle_extend.hpp"
#include "map/map_bundle.hpp"
#include "map/map_products.hpp"
#include "map/map_updates.hpp"
#include "msg/convert.hpp"
#include "nodes/node_config.hpp"
#include "nodes/products.hpp"
#include "nodes/registry.hpp"
#include "nodes/run_state.hpp"
#include "nodes/trajectory_log.hpp"
#include "runtime/record_log.hpp"

#include <adit/command_t.hpp>
#include <adit/features_t.hpp>
#include <adit/map_update_t.hpp>
#include <adit/pose_graph_t.hpp>
#include <spdlog/spdlog.h>

#include <atomic>
#include <deque>
#include <memory>

namespace adit::nodes {
namespace {

constexpr const char* kKeyframesKind = "loop_closer_keyframes";

// The loop closer owns the corrected map of a run: its keyframes are the submaps (each keyframe's cloud
// anchored to the keyframe), the pose graph places them. It answers save_map, publishes MAP_UPDATE for
// viewers, and checkpoints keyframes and graph so that a restart keeps what was mapped before it.
class LoopCloserNode : public runtime::Node, public WritesProducts, public WritesBundle {
 public:
  explicit LoopCloserNode(const Config& config)
      : Node("loop_closer"), closer_(loopCloserConfigFrom(config)),
        node_(loopCloserNodeConfigTable().read(config)),
        updates_(mapUpdateConfigFrom(config)), config_keys_(pipelineConfigKeys(config)),
        reloc_(relocNodeConfigTable().read(config)), state_("loop_closer") {
    subscribe<adit::odometry_t>("mapped", "ODOM_MAPPED", [this](const adit::odometry_t& m) { onMapped(m); });
    // The sweeps' LinK3D keypoints, which seed and check loop verification (loop.keypoints.use).
    if (closer_.config().keypoints.use)
      subscribe<adit::features_t>("features", "FEATURES", [this](const adit::features_t& m) { onFeatures(m); });
    // Extending a saved map: the relocaliser's measured poses in it are what join this run's map to it.
    if (reloc_.extending())
      subscribe<adit::odometry_t>("pose_in_map", "POSE_IN_MAP", [this](const adit::odometry_t& m) { onPoseInMap(m); },
                                  runtime::InputKind::Events);  // none while relocalising: gaps are normal
    subscribe<adit::command_t>("command", "MAPPER_COMMAND", [this](const adit::command_t& m) { onCommand(m); },
                               runtime::InputKind::Requests);
    advertise("loop", "LOOP_CLOSURE");
    advertise("graph", "POSE_GRAPH");
    advertise("map", "MAP_UPDATE");
  }

  std::vector<std::string> writeProducts(const std::string& out_dir) override {
    return writeMapProducts(closer_, uncorrected(), node_.map_voxel, out_dir);
  }
  bool writesMap() const override { return true; }
  // The run's own map, or (extending a saved map) the saved map joined with this run's new roadway.
  MapBundle mapBundle() override {
    MapBundle run = bundleFrom(closer_, node_.map_voxel, config_keys_);
    if (!reloc_.extending()) return run;
    MapBundle prior;
    try {
      prior = loadMapBundle(reloc_.prior_map);
      if (reloc_.extend.hold_saved_map) prior.map = loadBundleMap(reloc_.prior_map);  // else redrawn from keyframes
      BundleExtendReport r;
      MapBundle both = extendBundle(prior, run, closer_.correctedTrajectory(uncorrected()), anchors_, reloc_.extend, &r);
      setCount("extend_anchors_used", r.anchors_used);
      setCount("extend_keyframes_added", r.kept_keyframes);
      setCount("extend_keyframes_overlap", r.overlap_keyframes);
      spdlog::info("[loop_closer] extended {}: {} of {} keyframes added ({} on mapped roadway), {} anchors used, "
                   "{} map points and {:.0f} m of roadway added; saved keyframes moved up to {:.2f} m", reloc_.prior_map,
                   r.kept_keyframes, r.session_keyframes, r.overlap_keyframes, r.anchors_used, r.map_points_added,
                   r.added_roadway_m, r.saved_moved_max_m);
      return both;
    } catch (const BundleError& e) {
      throw std::runtime_error("cannot extend " + reloc_.prior_map + ": " + e.what());
    }
  }

  void onRunFolder(const runtime::RunFolder& folder) override {
    state_.setFolder(folder);
    std::string error;
    const bool resumed = state_.resume([this](const std::string& bytes) { return restore(bytes); }, error);
    if (resumed) {
      setCount("restarted", 1);  // also resumed from a given run folder without a restart
      setCount("recovered_keyframes", closer_.stats().keyframes);
      setCount("recovered_loops", static_cast<std::int64_t>(closer_.acceptedLoops().size()));
      spdlog::info("[loop_closer] resumed from {}: {} keyframes, {} loops, {} sweeps", state_.checkpointPath(),
                   closer_.stats().keyframes, closer_.acceptedLoops().size(), trajectory_.size());
    } else if (!error.empty()) {
      reportError("checkpoint_refused", error);
    }
    // Paged after the resume: the checkpoint's keyframes come back into memory and the oldest go out again.
    if (node_.clouds_in_memory > 0) {
      try {
        closer_.pageKeyframesTo(folder.file("loop_closer.clouds"), static_cast<std::size_t>(node_.clouds_in_memory));
      } catch (const std::exception& e) {
        reportError("cloud_paging_failed", std::string(e.what()) + " (keyframes stay in memory)");
      }
    }
  }

  std::string state() const override { return health().counters.count("restarted") ? "restarted" : "running"; }
  double helperCpuMs() const override { return closer_.workerCpuMs(); }

 protected:
  void onFinish() override {
    // Loop jobs still in flight are applied (and published) before anything is saved, live and in replay.
    if (!trajectory_.empty()) publishResult(trajectory_.back().utime, closer_.finish());
    countLoopJobs();  // the jobs finish() waited for
    if (!state_.live()) return;  // replay writes its products itself
    saveProducts({});  // first: what the user asked for, before the stop's grace time runs out
    checkpoint();
    state_.flush();
    reportCheckpoints();
  }

 private:
  // Jobs in flight and the wall time sweeps waited for the loop worker: STATUS only, replay's products never
  // carry them (the worker's CPU time is helper_cpu_ms, helperCpuMs()).
  void countLoopJobs() {
    setCount("loop_jobs_in_flight", static_cast<std::int64_t>(closer_.jobsInFlight()));
    setCount("loop_wait_ms", static_cast<std::int64_t>(closer_.waitedMs()));
  }

  void onPoseInMap(const adit::odometry_t& m) {
    if (!(m.flags & adit::odometry_t::FLAG_MAP_MEASURED)) return;  // carried by odometry: ties nothing
    const PoseEstimate measured = msg::fromMessage(m);
    if (measured.pose.matrix().allFinite()) anchors_.push_back({measured.utime, measured.pose});
  }

  // A sweep's features precede its mapped pose (the mapper needs them first); a few are kept until it comes.
  void onFeatures(const adit::features_t& m) {
    std::vector<Eigen::Vector3f> points;
    std::vector<LinK3dDescriptor> descriptors;
    msg::keypointsOf(m, points, descriptors);
    recent_keypoints_.emplace_back(m.header.utime,
                                   std::make_shared<const KeyframeKeypoints>(KeyframeKeypoints::encode(points, descriptors)));
    if (recent_keypoints_.size() > kRecentKeypoints) recent_keypoints_.pop_front();
  }

  // The keypoints of the sweep at utime (null if its FEATURES never came); older ones are dropped.
  KeyframeKeypointsPtr takeKeypoints(std::int64_t utime) {
    while (!recent_keypoints_.empty() && recent_keypoints_.front().first < utime) recent_keypoints_.pop_front();
    if (recent_keypoints_.empty() || recent_keypoints_.front().first != utime) return nullptr;
    KeyframeKeypointsPtr out = std::move(recent_keypoints_.front().second);
    recent_keypoints_.pop_front();
    return out;
  }

  void onMapped(const adit::odometry_t& m) {
    PoseEstimate mapped = msg::fromMessage(m);
    // The graph is built on uncorrected poses: undo the correction the mapper had already applied.
    mapped.pose = makePose(m.loop_correction_position, m.loop_correction_orientation).inverse() * mapped.pose;
    const LidarScan cloud = msg::featuresOf(m).cloud;
    trajectory_.push_back({mapped.utime, mapped.pose});
    // A keyframe is merged out of the graph only once its record is in the checkpoint log.
    if (state_.live()) closer_.keepKeyframesFrom(static_cast<std::int64_t>(keyframes_written_->load()));
    const LoopCloser::Result result = closer_.process(mapped, cloud, takeKeypoints(mapped.utime));
    publishResult(mapped.utime, result);
    if (const auto update = updates_.update(mapped.utime, closer_)) publishMapUpdate(*update);
    const LoopCloserStats& s = closer_.stats();
    const bool periodic = result.keyframe_added && node_.checkpoint_keyframes > 0 && s.keyframes % node_.checkpoint_keyframes == 0;
    if (state_.live() && (periodic || result.graph_updated)) checkpoint();
    if (state_.live()) reportCheckpoints();
    trajectory_.release();
    countLoopJobs();
    setCount("keyframes", s.keyframes);
    setCount("revisit_keyframes", s.revisit_keyframes);
    setCount("retired_keyframes", s.retired_keyframes);
    setCount("loop_candidates", s.candidates);
    setCount("loops_accepted", s.accepted);
    setCount("partial_loops", s.partial_loops);
    setCount("keypoint_seeds", s.keypoint_seeds);
    setCount("submaps_reused", s.submaps_reused);
    setCount("keypoint_loops", s.keypoint_loops);
    setCount("rejected_ambiguous", s.rejected_ambiguous);
    setCount("contested", s.contested);
    setCount("rejected_fitness", s.rejected_fitness);
    setCount("rejected_degenerate", s.rejected_degenerate);
    setCount("rejected_odometry_gate", s.rejected_odometry);
    setCount("rejected_pairwise", s.rejected_pairwise);
    setCount("invalid_sweeps", s.invalid_sweeps);
    const KeyframeCloudStore& clouds = closer_.clouds();
    setCount("cloud_memory_kb", static_cast<std::int64_t>(clouds.residentBytes() / 1024));
    setCount("clouds_paged", static_cast<std::int64_t>(clouds.pagedClouds()));
    setCount("cloud_page_errors", static_cast<std::int64_t>(clouds.pageErrors()));
    setCount("cloud_read_errors", static_cast<std::int64_t>(clouds.readErrors()));
    const ScanContextDatabase& contexts = closer_.contexts();
    setCount("scan_context_memory_kb", static_cast<std::int64_t>(contexts.residentBytes() / 1024));
    setCount("scan_contexts_paged", static_cast<std::int64_t>(contexts.pagedContexts()));
    setCount("scan_context_page_errors", static_cast<std::int64_t>(contexts.pageErrors()));
    setCount("scan_context_read_errors", static_cast<std::int64_t>(contexts.readErrors()));
    setCount("trajectory_poses_in_memory", static_cast<std::int64_t>(trajectory_.inMemory()));
  }

  void publishResult(std::int64_t utime, const LoopCloser::Result& result) {
    for (const LoopConstraint& loop : result.loops) {
      adit::loop_closure_t out = msg::toMessage(loop, utime);
      // Keyframes by their number in the order made, which merging older keyframes out does not shift.
      out.query_index = static_cast<std::int32_t>(closer_.keyframes()[static_cast<std::size_t>(loop.query_index)].seq);
      out.match_index = static_cast<std::int32_t>(closer_.keyframes()[static_cast<std::size_t>(loop.match_index)].seq);
      publish("loop", out);
    }
    if (result.graph_updated) publishGraph(utime, result);
  }

  // save_map [NAME]: the corrected map, trajectory and graph into the run folder, as NAME.pcd / .tum / .g2o
  // (default map.pcd, trajectory.tum, pose_graph.g2o). NAME must be a plain file name: a command comes from
  // anyone on the bus, and must not choose where the process writes.
  void onCommand(const adit::command_t& m) {
    if (!commandAuthentic("command", m)) return;
    if (m.command != "save_map" && m.command != "save_bundle") {
      reportError("unknown_command",
                  "unknown command '" + runtime::printableText(m.command) + "' (known: save_map, save_bundle)");
      return;
    }
    if (!m.argument.empty()) {
      const std::string problem = runtime::plainFileNameProblem(m.argument);
      if (!problem.empty()) {
        reportError("command_refused", "save_map '" + runtime::printableText(m.argument) + "' refused: " + problem +
                                           " (files go into the run folder " + state_.folder().dir + ")");
        return;
      }
    }
    if (m.command == "save_bundle") return saveBundle(m.argument.empty() ? "map_bundle" : m.argument);
    saveProducts(productNamesFor(m.argument));
  }

  // save_bundle [NAME]: a map bundle folder NAME (default map_bundle) in the run folder, for later runs'
  // --prior-map. Written into a temporary folder and renamed, so an older bundle of that name stays whole.
  void saveBundle(const std::string& name) {
    try {
      const std::string dir = state_.folder().file(name);
      writeMapBundle(mapBundle(), dir);
      count("bundles_saved");
      spdlog::info("[loop_closer] saved map bundle {} ({} keyframes)", dir, closer_.stats().keyframes);
    } catch (const std::exception& e) {
      reportError("save_failed", std::string("save_bundle: ") + e.what());
    }
  }

  void saveProducts(const MapProductNames& names) {
    try {
      writeMapProducts(closer_, uncorrected(), node_.map_voxel, state_.folder().dir, names);
      count("maps_saved");
      spdlog::info("[loop_closer] saved {} keyframes, {} loops: {}, {}, {} in {}", closer_.stats().keyframes,
                   closer_.acceptedLoops().size(), names.map, names.trajectory, names.graph, state_.folder().dir);
    } catch (const std::exception& e) {
      reportError("save_failed", std::string("save_map: ") + e.what());
    }
  }

  // Keyframes go to an append-only log (each written once); the checkpoint holds the rest and how many
  // keyframes it covers, so a checkpoint costs the new keyframes plus the graph, not the whole run. Both are
  // written on the writer thread (a slow disk must not stall loop detection); a job superseded before it
  // ran is covered by the next, which carries every keyframe the log does not hold yet.
  void checkpoint() {
    // Records are in keyframe number order (seq); keepKeyframesFrom keeps every unwritten one in the graph.
    const std::size_t first = keyframes_written_->load();
    std::vector<std::string> records;
    for (std::size_t seq = first; seq < static_cast<std::size_t>(closer_.stats().keyframes); ++seq) {
      const int k = closer_.indexOfKeyframe(static_cast<std::int64_t>(seq));
      if (k < 0) {
        reportError("checkpoint_failed", "keyframe " + std::to_string(seq) + " was merged out before it was written");
        return;
      }
      records.push_back(closer_.keyframeRecord(k));
    }
    TrajectoryLog::Chunk poses = trajectory_.unwritten();
    ByteWriter w;
    w.putString(closer_.saveState());
    w.put<std::uint64_t>(poses.first + poses.poses.size());  // the trajectory's length, its poses in the log
    state_.submit([this, first, records = std::move(records), poses = std::move(poses), payload = w.bytes()] {
      try {
        if (!keyframes_log_.isOpen()) keyframes_log_.create(keyframesPath(), kKeyframesKind, state_.folder().run_id);
        if (first > keyframes_log_.size()) return std::string("keyframe log behind its checkpoint");
        keyframes_log_.append({records.begin() + static_cast<std::ptrdiff_t>(keyframes_log_.size() - first), records.end()});
        keyframes_written_->store(keyframes_log_.size());
        trajectory_.write(poses, trajectoryPath(), state_.folder().run_id);
      } catch (const std::exception& e) {
        return std::string("keyframes or trajectory not written: ") + e.what();  // the previous checkpoint still matches
      }
      return state_.save(payload);
    });
  }

  void reportCheckpoints() {
    for (const std::string& e : state_.takeErrors()) reportError("checkpoint_failed", e);
    setCount("checkpoints", state_.saved());
  }

  std::string restore(const std::string& bytes) {
    ByteReader r(bytes);
    const std::string state = r.getString();
    const auto trajectory_length = r.get<std::uint64_t>();
    if (!r.ok() || !r.atEnd()) return "malformed checkpoint";
    const std::size_t n = LoopCloser::keyframesInState(state);
    const runtime::LoadedRecords records = runtime::loadRecords(keyframesPath(), kKeyframesKind, state_.folder().run_id, n);
    if (!records.error.empty()) return records.error;
    if (records.records.size() < n)
      return keyframesPath() + " holds " + std::to_string(records.records.size()) + " of the " + std::to_string(n) +
             " keyframes the checkpoint names";
    LoopCloser closer(closer_.config());
    if (!closer.restoreState(state, records.records)) return "malformed loop closer state";
    TrajectoryLog trajectory;
    const std::string error = trajectory.restore(trajectoryPath(), state_.folder().run_id, trajectory_length);
    if (!error.empty()) return error;
    try {
      keyframes_log_.continueAfter(keyframesPath(), n);  // cut keyframes written after the checkpoint
      keyframes_written_->store(n);
    } catch (const std::exception& e) {
      return e.what();
    }
    closer_ = std::move(closer);
    trajectory_ = std::move(trajectory);
    return "";
  }

  std::string keyframesPath() const { return state_.folder().file("loop_closer.keyframes"); }
  std::string trajectoryPath() const { return state_.folder().file("loop_closer.trajectory"); }
  // The per-sweep mapped poses before loop correction, read back from the run folder's log where needed.
  Trajectory uncorrected() const { return trajectory_.all(trajectoryPath(), state_.folder().run_id); }

  // One pose as a row of a message's position (3) and orientation (4) arrays.
  static void appendPose(const Eigen::Isometry3d& T, std::vector<std::vector<double>>& positions,
                         std::vector<std::vector<double>>& orientations) {
    std::vector<double> position(3), orientation(4);
    splitPose(T, position.data(), orientation.data());
    positions.push_back(std::move(position));
    orientations.push_back(std::move(orientation));
  }

  void publishGraph(std::int64_t utime, const LoopCloser::Result& result) {
    adit::pose_graph_t g;
    g.header = msg::makeHeader(utime, "world");
    g.num_nodes = static_cast<std::int32_t>(result.corrected_keyframes.size());
    for (const StampedPose& k : result.corrected_keyframes) {
      g.node_utime.push_back(k.utime);
      appendPose(k.pose, g.position, g.orientation);
    }
    splitPose(result.T_corrected_uncorrected, g.correction_position, g.correction_orientation);
    g.num_loops = static_cast<std::int32_t>(closer_.acceptedLoops().size());
    g.newest_loop = msg::toMessage(result.loop.value_or(LoopConstraint{}), utime);
    publish("graph", g);
  }

  void publishMapUpdate(const MapUpdate& update) {
    adit::map_update_t m;
    m.header = msg::makeHeader(update.utime, "world");
    m.num_submaps = update.num_submaps;
    m.num_loops = update.num_loops;
    for (const NewSubmap& s : update.added) {
      adit::map_submap_t sub;
      sub.id = s.where.id;
      sub.utime = s.where.utime;
      splitPose(s.where.pose, sub.position, sub.orientation);
      sub.num_points = static_cast<std::int32_t>(s.points.size());
      for (const Eigen::Vector3f& p : s.points) sub.points.push_back({p.x(), p.y(), p.z()});
      m.new_submaps.push_back(std::move(sub));
    }
    m.num_new = static_cast<std::int32_t>(m.new_submaps.size());
    for (const SubmapPose& s : update.moved) {
      m.moved_id.push_back(s.id);
      appendPose(s.pose, m.moved_position, m.moved_orientation);
    }
    m.num_moved = static_cast<std::int32_t>(m.moved_id.size());
    count("map_update_submaps", static_cast<std::int64_t>(update.added.size()));
    publish("map", m);
  }

  LoopCloser closer_;
  static constexpr std::size_t kRecentKeypoints = 16;
  std::deque<std::pair<std::int64_t, KeyframeKeypointsPtr>> recent_keypoints_;  // utime, keypoints
  LoopCloserNodeConfig node_;  // map voxel, checkpoint spacing, clouds kept in memory
  MapUpdateTracker updates_;
  std::map<std::string, std::string> config_keys_;  // every pipeline key, for the bundle's config.yaml
  RelocNodeConfig reloc_;
  Trajectory anchors_;  // extending: the relocaliser's measured poses in the saved map (one a metre, not checkpointed)
  runtime::RecordLog keyframes_log_;  // the writer thread's, once the run started
  std::shared_ptr<std::atomic<std::size_t>> keyframes_written_ = std::make_shared<std::atomic<std::size_t>>(0);
  TrajectoryLog trajectory_;  // the per-sweep poses; its log is written on state_'s writer thread
  RunState state_;  // after what its jobs use: its writer thread stops first
};

}  // namespace

std::unique_ptr<runtime::Node> makeLoopCloserNode(const Config& config) {
  return std::make_unique<LoopCloserNode>(config);
}

}  // namespace adit::nodes
