#include "nodes/mapper_node.hpp"

#include "core/byte_codec.hpp"
#include "core/geometry.hpp"
#include "eval/trajectory_io.hpp"
#include "io/atomic_file.hpp"
#include "io/pcd.hpp"
#include "features/preprocess.hpp"
#include "mapping/scan_to_map.hpp"
#include "msg/convert.hpp"
#include "nodes/node_config.hpp"
#include "nodes/products.hpp"
#include "nodes/run_state.hpp"

#include <adit/pose_graph_t.hpp>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>

namespace adit::nodes {
namespace {

class MapperNode : public runtime::Node, public WritesProducts {
 public:
  explicit MapperNode(const Config& config)
      : Node("mapper"), mapper_(mapperConfigFrom(config)),
        map_voxel_(mapperNodeConfigTable().read(config).map_voxel),
        // ODOM_MAPPED carries the sweep for the loop closer's keyframes, which it thins to 0.2 m itself
        // (loop.keyframe_voxel); keep this at or below that. 0 = forward it whole.
        forward_voxel_(mapperNodeConfigTable().read(config).forward_cloud_voxel),
        checkpoint_period_us_(toUtime(mapperNodeConfigTable().read(config).checkpoint_period_s)),
        state_("mapper") {
    subscribe<adit::odometry_t>("odometry", "ODOM_SCAN", [this](const adit::odometry_t& m) { onOdometry(m); });
    subscribe<adit::pose_graph_t>("graph", "POSE_GRAPH", [this](const adit::pose_graph_t& m) { onGraph(m); },
                                  runtime::InputKind::Events);
    advertise("mapped", "ODOM_MAPPED");
  }

  // Replay only (live, the loop closer owns the map): odometry.tum, trajectory.tum and the mapper's own
  // uncorrected map.pcd, both of which the loop closer, when it runs, replaces with its corrected ones.
  std::vector<std::string> writeProducts(const std::string& out_dir) override {
    namespace fs = std::filesystem;
    const std::string odometry = (fs::path(out_dir) / "odometry.tum").string();
    const std::string trajectory = (fs::path(out_dir) / "trajectory.tum").string();
    const std::string map = (fs::path(out_dir) / "map.pcd").string();
    const std::string covariance = (fs::path(out_dir) / "covariance.txt").string();
    eval::writeTum(odometry, uncorrected_);
    eval::writeTum(trajectory, corrected_);
    io::writeFileAtomically(covariance, covarianceText());
    if (!mapper_.keepsGlobalMap()) return {odometry, trajectory, covariance};
    std::vector<LidarPoint> points;
    for (const auto& p : mapper_.globalMap(map_voxel_)) points.push_back({p, 0.0f, 0, 0.0f});
    io::writePcd(map, points);
    return {odometry, trajectory, covariance, map};
  }
  bool writesMap() const override { return mapper_.keepsGlobalMap(); }
  // The loop closer's map (corrected keyframes) replaces ours: the global map would only cost memory.
  void mapWrittenLater() override { mapper_.dropGlobalMap(); }

  void onRunFolder(const runtime::RunFolder& folder) override {
    // Live, the loop closer owns the map (save_map, the map saved on stop); this process writes none.
    if (folder.live) mapper_.dropGlobalMap();
    state_.setFolder(folder);
    std::string error;
    const bool resumed = state_.resume([this](const std::string& bytes) { return restore(bytes); }, error);
    if (resumed) {
      setCount("restarted", 1);  // also resumed from a given run folder without a restart
      const ScanToMapMapper::State s = mapper_.state();
      setCount("recovered_map_points", static_cast<std::int64_t>(s.corners.size() + s.surfs.size()));
      spdlog::info("[mapper] resumed from {}: local map of {} points, last sweep at {}", state_.checkpointPath(),
                   s.corners.size() + s.surfs.size(), s.utime);
    } else if (!error.empty()) {
      reportError("checkpoint_refused", error);
    }
  }

  std::string state() const override { return health().counters.count("restarted") ? "restarted" : "running"; }
  double helperCpuMs() const override { return mapper_.helperCpuMs(); }

  // Live: a sweep's time from the bus to its mapped pose, the pipeline's latency (STATUS_MAPPER counters
  // points_to_mapped_*); the process also listens to LIDAR_POINTS for the arrival stamps.
  LatencyProbe latencyProbe() const override { return {"points_to_mapped", "LIDAR_POINTS", "mapped"}; }

 protected:
  void onFinish() override {
    if (!state_.live()) return;
    checkpoint();
    state_.flush();
    reportCheckpoints();
  }

 private:
  void onOdometry(const adit::odometry_t& m) {
    FeatureSet features = msg::featuresOf(m);
    const PoseEstimate mapped = mapper_.process(features, msg::fromMessage(m));
    // The loop closer needs the pose and the thinned sweep, not the LOAM sets.
    features.corner_less_sharp.clear();
    features.surf_less_flat.clear();
    if (forward_voxel_ > 0)
      features.cloud.points = features::voxelDownsample(features.cloud.points, static_cast<float>(forward_voxel_));
    if (mapped.flags & PoseEstimate::kRegistrationFailed) count("registration_failed");
    if (mapped.flags & PoseEstimate::kDegenerateTranslation) count("degenerate_translation");
    if (mapped.flags & PoseEstimate::kDegenerateRotation) count("degenerate_rotation");
    if (mapped.flags & PoseEstimate::kStandingStill) count("standing_still");
    if (mapper_.holdsTiltToGravity()) count("tilt_held_to_gravity");
    if (mapper_.gravityRejected() > 0) setCount("gravity_rejected", mapper_.gravityRejected());
    if (mapper_.gravityDisagreements() > 0) setCount("gravity_disagrees", mapper_.gravityDisagreements());
    adit::odometry_t out = msg::toMessage(mapped, &features);
    splitPose(applied_, out.loop_correction_position, out.loop_correction_orientation);
    publish("mapped", out);
    if (!state_.live()) {  // the per-sweep trajectories are replay's products only
      corrected_.push_back({mapped.utime, mapped.pose});
      uncorrected_.push_back({mapped.utime, applied_.inverse() * mapped.pose});
      covariances_.push_back({mapped.utime, mapped.covariance, mapped.flags});
    }
    if (state_.live() && checkpoint_period_us_ > 0 && mapped.utime - last_checkpoint_utime_ >= checkpoint_period_us_) {
      checkpoint();
      last_checkpoint_utime_ = mapped.utime;
    }
    reportCheckpoints();
  }

  // covariance.txt: per mapped pose its time (s, as in the TUM files), degeneracy flags (odometry_t's bits) and
  // the 6x6 covariance row-major, lidar frame, tangent order (tx ty tz rx ry rz). A degenerate direction
  // carries the variance of what held it (motion model or wheel), never the data's near-infinite one.
  std::string covarianceText() const {
    std::string text = "# t flags c00 c01 ... c55 (row-major 6x6, lidar frame, tx ty tz rx ry rz; m^2, m rad, rad^2)\n";
    char buf[64];
    for (const PoseCovariance& c : covariances_) {
      std::snprintf(buf, sizeof buf, "%.6f %d", toSeconds(c.utime), c.flags);
      text += buf;
      for (int i = 0; i < 36; ++i) {
        std::snprintf(buf, sizeof buf, " %.6g", c.covariance(i / 6, i % 6));
        text += buf;
      }
      text += '\n';
    }
    return text;
  }

  // The graph's correction is total (relative to uncorrected poses); apply what is new to us.
  void onGraph(const adit::pose_graph_t& m) {
    const Eigen::Isometry3d total = makePose(m.correction_position, m.correction_orientation);
    if (!total.matrix().allFinite()) {
      reportDrop("invalid_graph", "POSE_GRAPH with a non-finite correction: skipped");
      return;
    }
    mapper_.applyCorrection(total * applied_.inverse());
    applied_ = total;
    count("loop_corrections");
  }

  void checkpoint() {
    const ScanToMapMapper::State s = mapper_.state();
    ByteWriter w;
    w.put<std::int64_t>(s.utime);
    w.putPose(s.T_map_odom);
    w.putPose(s.previous_odometry);
    w.putPose(applied_);
    w.putPoints(s.corners);
    w.putPoints(s.surfs);
    w.putMatrix(s.gravity.down_sum);
    w.put<std::int32_t>(s.gravity.count);
    w.putMatrix(s.gravity.R_reference);
    state_.saveLater(w.bytes());
  }

  void reportCheckpoints() {
    for (const std::string& e : state_.takeErrors()) reportError("checkpoint_failed", e);
    setCount("checkpoints", state_.saved());
  }

  std::string restore(const std::string& bytes) {
    ByteReader r(bytes);
    ScanToMapMapper::State s;
    s.utime = r.get<std::int64_t>();
    s.T_map_odom = r.getPose();
    s.previous_odometry = r.getPose();
    const Eigen::Isometry3d applied = r.getPose();
    s.corners = r.getPoints<Eigen::Vector3d>();
    s.surfs = r.getPoints<Eigen::Vector3d>();
    if (!r.atEnd()) {  // a checkpoint written before the map's down was kept has none
      s.gravity.down_sum = r.getMatrix<Eigen::Vector3d>();
      s.gravity.count = r.get<std::int32_t>();
      s.gravity.R_reference = r.getMatrix<Eigen::Matrix3d>();
    }
    if (!r.ok() || !r.atEnd()) return "malformed mapper state";
    mapper_.restore(s);
    applied_ = applied;
    last_checkpoint_utime_ = s.utime;
    return "";
  }

  ScanToMapMapper mapper_;
  double map_voxel_;
  double forward_voxel_;
  std::int64_t checkpoint_period_us_;
  std::int64_t last_checkpoint_utime_ = -1;
  RunState state_;
  Eigen::Isometry3d applied_ = Eigen::Isometry3d::Identity();  // total loop correction applied so far
  Trajectory corrected_, uncorrected_;
  struct PoseCovariance {
    std::int64_t utime = 0;
    Matrix6d covariance;
    std::int32_t flags = 0;
  };
  std::vector<PoseCovariance> covariances_;
};

}  // namespace

std::unique_ptr<runtime::Node> makeMapperNode(const Config& config) { return std::make_unique<MapperNode>(config); }

}  // namespace adit::nodes
