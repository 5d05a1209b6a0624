// The loop-closure stage: keyframes from the mapper's poses, Scan Context candidates, geometric verification,
// consistency gates and a pose graph whose corrections go back to the mapper and into the final map.
//
// Per sweep: process(mapped pose, deskewed cloud). Every ~1 m / ~10 deg a keyframe is added with its
// downsampled cloud and Scan Context; a candidate becomes a loop only if
//   1. its Scan Context distance is below the threshold (database query excludes recent keyframes),
//   2. ICP of the query keyframe against the candidate's submap fits tightly and constrains all 6 directions
//      (or all but one translation: a partial loop, which constrains only what it observes),
//   3. the implied correction is plausible given the odometry uncertainty accumulated since the candidate
//      (Mahalanobis gate), and
//   4. it agrees with an accepted loop nearby, or with min_consistent_loops - 1 other pending loops.
// Roadways are repetitive: a false loop is worse than a missed one, and the defaults lean that way.
// Steps 2-4 and the graph optimisation run as a job on a worker, applied at a fixed later sweep
// (loop/loop_job.hpp): the sweeps never wait for ICP unless the job overruns loop.apply_delay_s.
#pragma once

#include "core/config_table.hpp"
#include "core/types.hpp"
#include "loop/compact_cloud.hpp"
#include "loop/keyframe_cloud_store.hpp"
#include "loop/keyframe_keypoints.hpp"
#include "loop/keypoint_seed.hpp"
#include "loop/loop_verifier.hpp"
#include "loop/odometry_chain.hpp"
#include "loop/pose_graph.hpp"
#include "loop/scan_context_database.hpp"

#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace adit {

struct LoopCloserConfig {
  // --- keyframes ---
  double keyframe_distance = 1.0;   // m of mapped motion between keyframes (loop.keyframe_distance)
  double keyframe_angle_deg = 10.0; // deg of mapped rotation between keyframes (loop.keyframe_angle_deg)
  // Voxel (m) of the cloud kept per keyframe for verification and the corrected map: 0.2 m keeps rock-wall
  // shape for point-to-plane normals at ~5-10k points per 16-beam keyframe.
  double keyframe_voxel = 0.2;
  // Quantisation step (m) of the kept clouds (loop/compact_cloud.hpp): int16 counts halve their memory, the
  // largest share of a long run's. 5 mm is 40x finer than the voxel and reaches 163 m from the keyframe.
  double keyframe_cloud_step = 0.005;
  // Build the Scan Context in a gravity-levelled frame (roll and pitch of the mapped pose removed), so that a
  // sloping roadway or a tilted robot does not shift heights between visits.
  bool level_scan_context = true;

  // --- place recognition ---
  ScanContextConfig scan_context;
  int candidates = 10;                    // ring-key neighbours ranked per query
  double max_scan_context_distance = 0.25;// accept candidates below this distance for verification
  int max_verifications = 2;              // best candidates verified by ICP per keyframe
  int exclude_recent_keyframes = 50;      // never match the newest N keyframes (~50 m of roadway)
  double exclude_recent_seconds = 30.0;   // nor those from the last T seconds (a robot standing still)
  int cooldown_keyframes = 3;             // after an accepted loop, skip detection for this many keyframes

  // --- revisits: memory bounded by the roadway mapped, not by the time driven ---
  // A keyframe within revisit_distance (corrected poses) of an older keyframe that keeps its cloud, while a loop
  // accepted within the last revisit_trust_keyframes keyframes ties the trajectory to that older part of the map,
  // keeps only its pose-graph node: its cloud and Scan Context serve its own loop search, then are dropped. The
  // map of a place is its first visit's. A robot patrolling a mapped roadway for hours then adds a graph node
  // (< 1 kB) per keyframe instead of ~40 kB. 0 keeps every keyframe's cloud.
  // On a patrolled loop, loops come a few keyframes apart but pause now and then for 30-60 keyframes (aliased
  // or rejected candidates); with a trust of 30 every such pause kept clouds on mapped roadway, and those
  // keyframes stayed in the graph for good and became later laps' loop matches: an hour of roadway-loop kept
  // 643 clouds (145 of them such lapses) and 872 graph nodes, APE 0.182 m. With 60: 498 clouds (5 lapses),
  // 722 nodes, APE 0.102 m. The mapper drifts ~0.3 % over those 60 m, far less than revisit_distance.
  double revisit_distance = 1.0;
  int revisit_trust_keyframes = 60;
  // A keyframe without a cloud (a revisit) older than the newest retire_after_keyframes is merged out of the
  // pose graph (loop/graph_merge.hpp), retire_batch at a time: the graph, the odometry chain and the Scan
  // Context database then follow the roadway mapped too, and the keyframe leaves only its final correction
  // (44 bytes, for the corrected trajectory). Taken as at least one more than exclude_recent_keyframes,
  // consistency_window and revisit_trust_keyframes (their windows count keyframes); 0 keeps every keyframe.
  int retire_after_keyframes = 200;
  int retire_batch = 50;

  // --- scheduling (loop/loop_job.hpp) ---
  // Verification and graph optimisation run as a job; its outcome is applied at the first sweep this much
  // sensor time after the keyframe (0: within the same sweep, the single-threaded schedule). The output
  // depends only on the input; the delay is how long the worker may take before the sweeps wait for it.
  double apply_delay_s = 2.0;
  bool worker_thread = true;  // run the jobs on a worker thread (false: inline, same results)

  // --- verification ---
  LoopVerifierConfig verifier;
  // LinK3D keypoints (FEATURES) seed and check the verification (loop/keypoint_seed.hpp): their seed is tried
  // when the Scan Context and graph seeds do not fit; when those fit and the keypoints put the query elsewhere,
  // ICP runs from the keypoints' seed too: two accepted fits in different places that the odometry gate both
  // allows are an aliased place, refused; if it allows one, that one is the loop.
  KeypointSeedConfig keypoints;
  // A fit that pins every direction but one translation (the axis of a smooth straight roadway) joins the graph
  // as a partial loop: its covariance along that axis is partial_loop_axis_sigma, so it corrects the cross-
  // section, the height and the heading where a full loop would be refused, and leaves the position along the
  // roadway to the odometry.
  // Along the free axis the loop takes the graph's relative pose (what ICP slid to there is arbitrary, and a
  // slide of tens of metres times the axis' small error would leak into the cross-section), and the graph must
  // put the two keyframes within partial_loop_max_axis_offset of each other along it: the roadway is taken as
  // straight over that span, not over the whole featureless stretch.
  bool partial_loops = true;
  double partial_loop_axis_sigma = 100.0;  // m
  double partial_loop_max_axis_offset = 10.0;  // m

  // --- consistency ---
  // Odometry step noise added to each keyframe step (random-walk model, per sqrt of metres travelled) on top of
  // the mapper's covariance: keeps the graph honest when the mapper is over-confident. 2 cm and 0.12 deg
  // per sqrt(m) correspond to a LOAM-class drift of ~1 % over a few hundred metres.
  double odometry_translation_sigma = 0.02;  // m / sqrt(m)
  double odometry_rotation_sigma = 0.002;    // rad / sqrt(m)
  double odometry_min_translation_sigma = 0.01; // m per step
  double odometry_min_rotation_sigma = 0.001;   // rad per step
  bool use_mapper_covariance = true;  // add the mapper's per-sweep covariances of the step (identity = unset)
  // Loop measurement noise (ICP of a verified loop): a few cm and a fraction of a degree.
  double loop_translation_sigma = 0.05;  // m
  double loop_rotation_sigma = 0.01;     // rad
  // Mahalanobis gate of the loop against the odometry (chi-square, 6 dof; 22.46 = 99.9 %).
  double max_odometry_chi2 = 22.46;
  // A loop is accepted when consistent (pairwise chi-square below max_pair_chi2) with an accepted loop whose
  // query lies within consistency_window keyframes, or with min_consistent_loops - 1 pending verified loops
  // there. 2 = never trust a single match in a repetitive roadway.
  int min_consistent_loops = 2;
  int consistency_window = 20;
  double max_pair_chi2 = 22.46;

  // --- pose graph ---
  PoseGraphConfig graph;
};

// Keys "loop.<field>" (see README); reading validates them (throws ConfigError).
const ConfigTable<LoopCloserConfig>& loopCloserConfigTable();
LoopCloserConfig loopCloserConfigFrom(const Config& config);

// Covariance of a relative pose over `metres` of driving under the odometry random walk (odometry_*_sigma).
Matrix6d odometryDriftCovariance(const LoopCloserConfig& config, double metres);
// Covariance of one verified loop measurement (loop_*_sigma).
Matrix6d loopMeasurementCovariance(const LoopCloserConfig& config);
// The same for a partial loop, free along `axis` (unit, the query keyframe's frame).
Matrix6d partialLoopCovariance(const LoopCloserConfig& config, const Eigen::Vector3d& axis);
// A loop whose information leaves a translation with a standard deviation above 1 m: a partial loop.
bool isPartialLoop(const LoopConstraint& loop);
// The part of `translation` (the query keyframe's frame) that the loop measures: without its free axis.
Eigen::Vector3d measuredPart(const LoopConstraint& loop, const Eigen::Vector3d& translation);

struct LoopCloserStats {
  int sweeps = 0;
  int invalid_sweeps = 0;      // non-finite pose: skipped
  int keyframes = 0;
  int queries = 0;             // keyframes searched for a place match
  int candidates = 0;          // candidates under the Scan Context threshold
  int rejected_fitness = 0;    // ICP did not fit (or too few points)
  int rejected_degenerate = 0; // ICP fit but left a direction unconstrained
  int rejected_odometry = 0;   // Mahalanobis gate against the odometry uncertainty
  int rejected_pairwise = 0;   // inconsistent with an accepted loop nearby
  int pending = 0;             // verified loops waiting for a consistent partner
  int accepted = 0;
  int partial_loops = 0;       // accepted loops that leave one translation free (partial_loops)
  int optimizations = 0;
  int revisit_keyframes = 0;   // keyframes that kept only their graph node (revisit_distance)
  // LinK3D (loop.keypoints) and consensus; like revisit_keyframes and partial_loops not in checkpoints
  // (restart from 0).
  int keypoint_seeds = 0;       // candidates whose keypoints gave a seed
  int keypoint_loops = 0;       // verified fits that only the keypoints' seed found
  int rejected_ambiguous = 0;   // two accepted fits in different places, both within the odometry gate
  int contested = 0;            // enough loops agreed but waited: as many waiting loops contradicted them
  int retired_keyframes = 0;    // merged out of the graph (retire_after_keyframes)
  int submaps_reused = 0;       // candidates verified against a submap target kept from an earlier job (not
                                // checkpointed either)
};

class LoopScheduler;

class LoopCloser {
 public:
  struct Result {
    bool keyframe_added = false;
    std::optional<LoopConstraint> loop;  // the last loop accepted by this call
    std::vector<LoopConstraint> loops;   // every loop accepted by this call (a pending one may join)
    bool graph_updated = false;
    std::vector<StampedPose> corrected_keyframes;  // all keyframes, filled only when graph_updated
    // Correction of the newest keyframe: corrected pose = T_corrected_uncorrected * mapped pose.
    Eigen::Isometry3d T_corrected_uncorrected = Eigen::Isometry3d::Identity();
  };

  explicit LoopCloser(const LoopCloserConfig& config = {});
  ~LoopCloser();  // waits for the job running on the worker
  LoopCloser(LoopCloser&&) noexcept;
  LoopCloser& operator=(LoopCloser&&) noexcept;

  // cloud: deskewed sweep in the lidar frame at mapped.utime; keypoints: the sweep's LinK3D keypoints (FEATURES),
  // null if unknown: kept with a keyframe's cloud to seed and check verification (loop.keypoints).
  Result process(const PoseEstimate& mapped, const LidarScan& cloud, KeyframeKeypointsPtr keypoints = nullptr);
  // End of input: applies every job still in flight (waiting for the worker).
  Result finish();
  // Loop jobs posted but not applied yet, the wall time (ms, measurement only) sweeps waited for them, and the
  // CPU time (ms, measurement only) the jobs took on the worker thread (0 with loop.worker_thread false, when
  // they run inside process() and count in its thread's CPU time).
  std::size_t jobsInFlight() const;
  double waitedMs() const;
  double workerCpuMs() const;

  // Per-sweep poses corrected by interpolating (in time) the corrections of the surrounding keyframes.
  Trajectory correctedTrajectory(const Trajectory& uncorrected) const;
  // Keyframe clouds at their corrected poses, voxel-downsampled (voxel <= 0: no downsampling).
  std::vector<Eigen::Vector3f> correctedMap(double voxel) const;

  // keyframes()[k] is keyframe index k: the order of the graph's nodes, which shifts when older keyframes are
  // merged out (loop.retire_after_keyframes). seq is a keyframe's number in the order keyframes were made
  // (0, 1, 2, ...), which never changes: what checkpoints and messages name a keyframe by.
  struct Keyframe {
    std::int64_t utime = 0;
    Eigen::Isometry3d uncorrected = Eigen::Isometry3d::Identity();  // mapped T_world_lidar
    std::int64_t seq = 0;
  };
  const std::vector<Keyframe>& keyframes() const { return keyframes_; }
  // Index of the keyframe numbered seq, or -1 if it was merged out (or never made).
  int indexOfKeyframe(std::int64_t seq) const;
  // Keyframes numbered seq and later are never merged out (a live process's keyframes not yet in its
  // checkpoint log, whose records must still be written). Default: no limit.
  void keepKeyframesFrom(std::int64_t seq) { keep_from_seq_ = seq; }
  // Keyframe k's cloud (downsampled, lidar frame; empty for a revisit), from memory or the page file.
  CompactCloud keyframeCloud(int k) const { return clouds_.cloud(k); }
  // Keyframe k's LinK3D keypoints (empty for a revisit or a sweep without them).
  KeyframeKeypoints keyframeKeypoints(int k) const;
  // A live process's memory: the clouds and keypoints of all but the newest `resident` keyframes go to a page
  // file (loop/keyframe_cloud_store.hpp), their Scan Contexts to another (path + ".sc",
  // loop/scan_context_database.hpp). Throws std::runtime_error if a file cannot be created.
  void pageKeyframesTo(const std::string& path, std::size_t resident);
  const KeyframeCloudStore& clouds() const { return clouds_; }
  const ScanContextDatabase& contexts() const { return database_; }
  const PoseGraph& graph() const { return graph_; }
  ScanContext keyframeContext(int keyframe) const { return database_.context(keyframe); }
  const std::vector<LoopConstraint>& acceptedLoops() const { return accepted_; }
  const LoopCloserStats& stats() const { return stats_; }
  const LoopCloserConfig& config() const { return config_; }
  Eigen::Isometry3d correction(int keyframe) const;  // X_k * U_k^-1

  // The state as bytes for a checkpoint (loop_closer_state.cpp), in two parts: one record per keyframe
  // (pose, cloud, Scan Context, step covariance: written once, appended as keyframes come), and the rest
  // (graph poses and edges, loops, counters: small, rewritten). restoreState() takes the first
  // keyframes (as many as the state names) and leaves this object unchanged if anything is malformed.
  std::string keyframeRecord(int keyframe) const;
  std::string saveState() const;
  bool restoreState(const std::string& state, const std::vector<std::string>& keyframe_records);
  // Keyframes a saved state refers to (0 if malformed).
  static std::size_t keyframesInState(const std::string& state);

 private:
  bool isKeyframe(const Eigen::Isometry3d& pose) const;
  ScanContext addKeyframe(const PoseEstimate& mapped, const LidarScan& cloud, KeyframeKeypointsPtr keypoints);
  bool isRevisit(int keyframe) const;
  void retireRevisits(Result& result);  // loop_closer_retire.cpp
  Matrix6d stepCovariance(const Eigen::Isometry3d& new_pose) const;
  void submitJob(int query, const ScanContext& context);
  void applyDue(std::int64_t utime, bool all, Result& result);
  LoopScheduler& scheduler();

  LoopCloserConfig config_;
  std::vector<Keyframe> keyframes_;
  KeyframeCloudStore clouds_;  // [k]: keyframe k's cloud and LinK3D keypoints (dropped together for a revisit)
  OdometryChain chain_;
  PoseGraph graph_;
  ScanContextDatabase database_;
  // As of the newest applied job (the jobs keep their own book, loop/loop_job.hpp): what checkpoints save.
  std::vector<LoopConstraint> accepted_;
  std::vector<LoopConstraint> pending_;
  std::vector<std::pair<Eigen::Isometry3d, Matrix6d>> sweeps_since_keyframe_;  // pose, covariance
  int last_loop_query_ = -1000000;
  LoopCloserStats stats_;
  std::unique_ptr<LoopScheduler> scheduler_;  // created with the first job
  // Keyframes merged out of the graph, in time order, for correctedTrajectory: each one's correction relative
  // to that of a keyframe still in the graph (the nearest older one when it was merged out), so that it moves
  // with that part of the map when later loops move it. C_this = C_anchor * offset.
  struct RetiredKeyframe {
    std::int64_t utime = 0;
    std::int64_t anchor_seq = 0;
    float translation[3] = {0, 0, 0};  // offset
    float rotation[4] = {0, 0, 0, 1};  // offset, quaternion x y z w
    Eigen::Isometry3d offset() const;
    void setOffset(const Eigen::Isometry3d& offset);
  };
  std::vector<RetiredKeyframe> retired_;
  std::int64_t keep_from_seq_ = std::numeric_limits<std::int64_t>::max();
};

}  // namespace adit
