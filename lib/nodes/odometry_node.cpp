#include "nodes/odometry_node.hpp"

#include "core/byte_codec.hpp"
#include "features/preprocess.hpp"
#include "msg/convert.hpp"
#include "nodes/sample_buffer.hpp"
#include "nodes/node_config.hpp"
#include "nodes/run_state.hpp"
#include "features/deskew.hpp"
#include "odometry/gyro_bias.hpp"
#include "odometry/initial_guess.hpp"
#include "registration/pose_increment.hpp"
#include "odometry/scan_to_scan.hpp"
#include "odometry/specific_force.hpp"
#include "odometry/wheel_motion.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <deque>
#include <optional>

namespace adit::nodes {
namespace {

// The lidar axis (0 x, 1 y, 2 z) nearest to a direction.
int nearestAxis(const Eigen::Vector3d& direction) {
  int axis = 0;
  direction.cwiseAbs().maxCoeff(&axis);
  return axis;
}

class OdometryNode : public runtime::Node {
 public:
  explicit OdometryNode(const Config& config)
      : Node("odometry"),
        odometry_(scanToScanConfigFrom(config)),
        guess_config_(initialGuessConfigFrom(config)),
        imu_(odometryNodeConfigTable().read(config).imu_keep_s),
        wheel_buffer_(odometryNodeConfigTable().read(config).imu_keep_s),
        wheel_(wheelMotionConfigTable().read(config)),
        gyro_bias_(gyroBiasConfigTable().read(config)),
        state_("odometry") {
    const OdometryNodeConfig node = odometryNodeConfigTable().read(config);
    forward_voxel_ = node.forward_cloud_voxel;
    checkpoint_period_us_ = toUtime(node.checkpoint_period_s);
    max_extrapolation_s_ = node.max_extrapolation_s;
    subscribe<adit::features_t>("features", "FEATURES", [this](const adit::features_t& m) { onFeatures(m); });
    subscribe<adit::imu_t>("imu", "IMU", [this](const adit::imu_t& m) { imu_.add(m); });
    // Optional: a robot without wheel odometry publishes nothing here.
    subscribe<adit::wheel_odom_t>("wheel", "WHEEL_ODOM", [this](const adit::wheel_odom_t& m) { wheel_buffer_.add(m); });
    advertise("odometry", "ODOM_SCAN");
  }

  void onRunFolder(const runtime::RunFolder& folder) override {
    state_.setFolder(folder);
    std::string error;
    const bool resumed = state_.resume([this](const std::string& bytes) { return restore(bytes); }, error);
    if (resumed) {
      setCount("restarted", 1);  // also resumed from a given run folder without a restart
      spdlog::info("[odometry] resumed from {}: pose ({:.2f}, {:.2f}, {:.2f}) at {}", state_.checkpointPath(),
                   resume_->pose.translation().x(), resume_->pose.translation().y(),
                   resume_->pose.translation().z(), resume_->utime);
    } else if (!error.empty()) {
      reportError("checkpoint_refused", error);
    }
  }

  std::string state() const override { return health().counters.count("restarted") ? "restarted" : "running"; }
  double helperCpuMs() const override { return odometry_.helperCpuMs(); }

 protected:
  // A gap in the sweeps (the feature stage restarted, the sensor stalled): start registration over, but
  // in the same odometry frame, from the last pose moved on at the last velocity. Never back to identity.
  // A gap in the sweeps (a stalled sensor, a restarted feature stage) resets nothing: the odometry predicts
  // the gap with its averaged velocity and registers the next sweep against the last one, which recovers the
  // real motion (measured: 0.08 m off after a 10 s stall; resetting and extrapolating alone left 12.7 m, and
  // resetting to the identity made the mapper jump back by the whole distance). A restart of the odometry
  // itself resumes from its checkpoint (useRunFolder).
  void onTimeJump(const std::string& port) override {
    if (port == "imu") imu_.clear();
    if (port == "wheel") wheel_buffer_.clear();
  }

  void onFinish() override {
    if (state_.live() && odometry_.lastUtime() >= 0) checkpoint();
    state_.flush();
    reportCheckpoints();
  }

 private:
  struct Resume {
    std::int64_t utime = 0;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    Vector6d velocity = Vector6d::Zero();
  };

  void onFeatures(const adit::features_t& m) {
    FeatureSet features = msg::fromMessage(m);
    if (resume_) resumeFrom(*resume_, features.utime);
    const std::vector<ImuSample> raw_imu = imu_.samples();
    // The gyro seeds (and weighs) the registration only with its bias removed, once a stop has measured it.
    const std::vector<ImuSample> imu = gyro_bias_.known() ? withoutGyroBias(raw_imu, gyro_bias_.bias()) : raw_imu;
    const InitialGuess guess = initialGuess(previous_ ? &*previous_ : nullptr, features,
                                            odometry_.predictMotion(features.utime),
                                            odometry_.hasVelocity(features.utime), imu, guess_config_);
    count("link3d_matches", guess.link3d_matches);
    if (guess.flags & PoseEstimate::kSeededByLinK3d) count("seeded_by_link3d");
    if (guess.flags & PoseEstimate::kSeededByImu) count("seeded_by_imu");
    const std::optional<WheelMotionEstimate> wheel = wheelMotion(features.utime, guess);
    const Eigen::Isometry3d before = odometry_.pose();
    const std::int64_t previous_utime = odometry_.lastUtime();
    const std::optional<RotationPrior> gyro = gyroRotation(imu, previous_utime, features.utime);
    if (gyro) count("gyro_rotation_weighed");
    PoseEstimate pose = odometry_.process(
        features, guess.T_prev_curr, guess.flags,
        wheel ? std::optional<MeasuredMotion>(MeasuredMotion{wheel->T_prev_curr, wheel->sigma_translation_m}) : std::nullopt,
        gyro);
    // The step between the registrations' own poses: the reported pose may be held (standstill).
    const Eigen::Isometry3d step = before.inverse() * odometry_.pose();
    if (previous_utime >= 0) {
      // The accelerometer for the mapper's gravity (mapping/gravity.hpp).
      pose.specific_force = integrateSpecificForce(raw_imu, previous_utime, features.utime, step.linear().transpose(),
                                                   guess_config_.R_lidar_imu, guess_config_.max_imu_gap_s);
      gyro_bias_.observe(raw_imu, previous_utime, features.utime, step,
                         !(pose.flags & PoseEstimate::kRegistrationFailed));
      if (gyro_bias_.known()) {
        setCount("gyro_bias_stops", gyro_bias_.restPeriods());
        setCount("gyro_bias_mdeg_s", static_cast<std::int64_t>(std::lround(gyro_bias_.bias().norm() * 180e3 / M_PI)));
        setCount("gyro_bias_sigma_mdeg_s", static_cast<std::int64_t>(std::lround(gyro_bias_.biasSigma() * 180e3 / M_PI)));
      }
    }
    if (pose.flags & PoseEstimate::kRegistrationFailed) count("registration_failed");
    if (odometry_.referenceKept()) count("reference_kept");
    if (pose.flags & PoseEstimate::kDegenerateTranslation) {
      count("degenerate_translation");
      count(std::string("degenerate_along_") + "xyz"[nearestAxis(odometry_.weakestTranslationDirection())]);
    }
    if (pose.flags & PoseEstimate::kDegenerateRotation) count("degenerate_rotation");
    if (pose.flags & kPoseHeldToWheel) count("held_to_wheel");
    if (pose.flags & PoseEstimate::kStandingStill) count("standing_still");
    if (previous_utime >= 0 && !(pose.flags & PoseEstimate::kRegistrationFailed)) {
      const Eigen::Vector3d& ev = pose.translation_eigenvalues;  // ascending
      const bool degenerate = (pose.flags & PoseEstimate::kDegenerateTranslation) != 0;
      const double observed = degenerate || !(ev[2] > 0.0) ? 0.0 : ev[0] / ev[2];
      wheel_.observe(step, observed, toSeconds(features.utime - previous_utime), wheel);
    }
    reportWheel();
    previous_ = features;
    // The mapper needs the less-sharp / less-flat sets and the thinned sweep (odometry_t carries only those).
    features.corner_sharp.clear();
    features.surf_flat.clear();
    if (forward_voxel_ > 0)
      features.cloud.points = features::voxelDownsample(features.cloud.points, static_cast<float>(forward_voxel_));
    adit::odometry_t out = msg::toMessage(pose, &features);
    publish("odometry", out);
    if (state_.live() && pose.utime - last_checkpoint_utime_ >= checkpoint_period_us_) checkpoint();
    reportCheckpoints();
  }

  // The gyro's rotation R_prev_curr over the interval, bias-corrected once a stop has measured the bias, with
  // its uncertainty, for the registration to weigh: none with the weighing off or where the samples do not
  // cover the interval.
  std::optional<RotationPrior> gyroRotation(const std::vector<ImuSample>& imu, std::int64_t previous, std::int64_t utime) const {
    if (previous < 0 || imu.empty() || !(odometry_.config().gyro_rotation_sigma_rad > 0.0)) return std::nullopt;
    const double interval = toSeconds(utime - previous);
    const auto rotations = features::imuRotations(imu, utime, {-interval}, guess_config_.R_lidar_imu, guess_config_.max_imu_gap_s);
    if (rotations.empty()) return std::nullopt;
    // rotations[0] is R_curr_prev.
    return RotationPrior{rotations.front().conjugate().toRotationMatrix(),
                         gyro_bias_.rotationSigma(odometry_.config().gyro_rotation_sigma_rad, interval)};
  }

  // The wheel's motion since the previous sweep (none without WHEEL_ODOM, before two sweeps, or when the
  // readings are distrusted), with the IMU's rotation when the seed has one.
  std::optional<WheelMotionEstimate> wheelMotion(std::int64_t utime, const InitialGuess& guess) {
    const std::int64_t previous = odometry_.lastUtime();
    if (wheel_buffer_.empty() || previous < 0) return std::nullopt;
    std::optional<Eigen::Matrix3d> rotation;
    if (guess.T_prev_curr && (guess.flags & PoseEstimate::kSeededByImu)) rotation = guess.T_prev_curr->linear();
    return wheel_.motion(wheel_buffer_.samples(), previous, utime, rotation);
  }

  void reportWheel() {
    const WheelCounters& c = wheel_.counters();
    if (c.used + c.gaps + c.distrusted + c.nonfinite + c.unordered == 0) return;  // no wheel on this robot
    setCount("wheel_used", c.used);
    setCount("wheel_calibrations", c.calibrations);
    setCount("wheel_gap", c.gaps);
    setCount("wheel_stuck", c.stuck);
    setCount("wheel_disagrees", c.disagreements);
    setCount("wheel_distrusted", c.distrusted);
    setCount("wheel_nonfinite", c.nonfinite);
    setCount("wheel_unordered", c.unordered);
    setCount("wheel_scale_ppm", static_cast<std::int64_t>(std::lround(wheel_.scale() * 1e6)));
  }

  void resumeFrom(const Resume& r, std::int64_t utime) {
    const double gap_s = toSeconds(utime - r.utime);
    Eigen::Isometry3d pose = r.pose;
    if (gap_s > 0 && gap_s <= max_extrapolation_s_) pose = applyIncrement(r.pose, r.velocity * gap_s);
    odometry_.resumeAt(pose);
    previous_.reset();
    resume_.reset();
    count("resumed");
  }

  void checkpoint() {
    ByteWriter w;
    w.put<std::int64_t>(odometry_.lastUtime());
    w.putPose(odometry_.pose());
    w.putMatrix(odometry_.lastVelocity());
    state_.saveLater(w.bytes());
    last_checkpoint_utime_ = odometry_.lastUtime();
  }

  void reportCheckpoints() {
    for (const std::string& e : state_.takeErrors()) reportError("checkpoint_failed", e);
    setCount("checkpoints", state_.saved());
  }

  std::string restore(const std::string& bytes) {
    ByteReader r(bytes);
    Resume resume;
    resume.utime = r.get<std::int64_t>();
    resume.pose = r.getPose();
    resume.velocity = r.getMatrix<Vector6d>();
    if (!r.ok() || !r.atEnd() || !resume.velocity.allFinite()) return "malformed odometry state";
    resume_ = resume;
    last_checkpoint_utime_ = resume.utime;
    return "";
  }

  ScanToScanOdometry odometry_;
  InitialGuessConfig guess_config_;
  ImuBuffer imu_;
  WheelBuffer wheel_buffer_;
  WheelMotion wheel_;
  GyroBiasEstimator gyro_bias_;
  double forward_voxel_ = 0.1;
  std::int64_t checkpoint_period_us_ = 500000;
  double max_extrapolation_s_ = 5.0;
  std::int64_t last_checkpoint_utime_ = -1;
  RunState state_;
  std::optional<Resume> resume_;
  std::optional<FeatureSet> previous_;
};

}  // namespace

std::unique_ptr<runtime::Node> makeOdometryNode(const Config& config) { return std::make_unique<OdometryNode>(config); }

}  // namespace adit::nodes
