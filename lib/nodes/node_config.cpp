#include "nodes/node_config.hpp"

#include "features/feature_config.hpp"
#include "loop/loop_closer.hpp"
#include "map/map_updates.hpp"
#include "map/relocaliser.hpp"
#include "mapping/scan_to_map.hpp"
#include "odometry/gyro_bias.hpp"
#include "odometry/initial_guess.hpp"
#include "odometry/scan_to_scan.hpp"
#include "odometry/wheel_motion.hpp"

namespace adit::nodes {

const ConfigTable<InputCheckConfig>& inputCheckConfigTable() {
  using N = InputCheckConfig;
  static const ConfigTable<N> table = [] {
    ConfigTable<N> t("input");
    t.add("max_future_s", &N::max_future_s, above(0), "s", "a stamp further ahead of the newest sensor time is held until the next messages confirm it")
     .add("confirm_messages", &N::confirm_messages, between(1, 100), "", "messages that must continue from a held stamp before it is adopted")
     .add("max_step_periods", &N::max_step_periods, above(1), "", "a sensor-stream step longer than this many typical periods needs the same confirmation")
     .add("max_seq_gap", &N::max_seq_gap, atLeast(1), "", "a sequence gap above this is a restarted publisher (seq_reset), not lost input")
     .add("max_elements", &N::max_elements, atLeast(1), "", "largest array a message may announce (elements, all dimensions together)")
     .add("max_string_bytes", &N::max_string_bytes, atLeast(1), "B", "largest string a message may announce on the wire")
     .add("max_text_length", &N::max_text_length, atLeast(1), "B", "longest text field accepted (command arguments, frame ids, STATUS text)")
     .add("max_angular_velocity", &N::max_angular_velocity, above(0), "rad/s", "IMU rates beyond this are refused as invalid_range")
     .add("max_acceleration", &N::max_acceleration, above(0), "m/s^2", "IMU accelerations beyond this are refused as invalid_range")
     .add("max_wheel_speed", &N::max_wheel_speed, above(0), "m/s", "wheel odometry speeds beyond this are refused as invalid_range");
    return t;
  }();
  return table;
}

runtime::InputChecks inputChecksFrom(const Config& config) {
  const InputCheckConfig c = inputCheckConfigTable().read(config);
  runtime::InputChecks checks;
  checks.max_future_s = c.max_future_s;
  checks.confirm_messages = c.confirm_messages;
  checks.max_step_periods = c.max_step_periods;
  checks.max_seq_gap = c.max_seq_gap;
  checks.wire.max_elements = c.max_elements;
  checks.wire.max_string_bytes = c.max_string_bytes;
  checks.values.max_string_length = static_cast<std::size_t>(c.max_text_length);
  checks.values.max_angular_velocity = c.max_angular_velocity;
  checks.values.max_acceleration = c.max_acceleration;
  checks.values.max_wheel_speed = c.max_wheel_speed;
  return checks;
}

const ConfigTable<FeatureNodeConfig>& featureNodeConfigTable() {
  using N = FeatureNodeConfig;
  static const ConfigTable<N> table = [] {
    ConfigTable<N> t("features.node");
    t.add("imu_keep_s", &N::imu_keep_s, above(0), "s", "IMU kept beyond a sweep's span for deskewing")
     .add("max_prior_age_s", &N::max_prior_age_s, atLeast(0), "s", "an odometry pose older than this before a sweep is not used as motion prior")
     .add("map_cloud_voxel", &N::map_cloud_voxel, atLeast(0), "m", "voxel of the sweep carried on FEATURES for the maps (0 = whole)");
    return t;
  }();
  return table;
}

const ConfigTable<OdometryNodeConfig>& odometryNodeConfigTable() {
  using N = OdometryNodeConfig;
  static const ConfigTable<N> table = [] {
    ConfigTable<N> t("odometry.node");
    t.add("imu_keep_s", &N::imu_keep_s, above(0), "s", "IMU kept for the rotation seed between sweeps")
     .add("forward_cloud_voxel", &N::forward_cloud_voxel, atLeast(0), "m", "voxel of the sweep forwarded on ODOM_SCAN (0 = as received, thinned by the feature stage)")
     .add("checkpoint_period_s", &N::checkpoint_period_s, atLeast(0), "s", "sensor time between pose checkpoints in live runs (0 = on stop only)")
     .add("max_extrapolation_s", &N::max_extrapolation_s, atLeast(0), "s", "longest gap the pose is carried across at the last velocity");
    return t;
  }();
  return table;
}

const ConfigTable<MapperNodeConfig>& mapperNodeConfigTable() {
  using N = MapperNodeConfig;
  static const ConfigTable<N> table = [] {
    ConfigTable<N> t("mapping.node");
    t.add("map_voxel", &N::map_voxel, atLeast(0), "m", "voxel of map.pcd written by the mapper (0 = the global map as is)")
     .add("forward_cloud_voxel", &N::forward_cloud_voxel, atLeast(0), "m", "voxel of the sweep forwarded on ODOM_MAPPED (0 = whole)")
     .add("checkpoint_period_s", &N::checkpoint_period_s, atLeast(0), "s", "sensor time between local-map checkpoints in live runs (0 = on stop only)");
    return t;
  }();
  return table;
}

const ConfigTable<LoopCloserNodeConfig>& loopCloserNodeConfigTable() {
  using N = LoopCloserNodeConfig;
  static const ConfigTable<N> table = [] {
    ConfigTable<N> t("loop");
    t.add("map_voxel", &N::map_voxel, atLeast(0), "m", "voxel of the loop-corrected map.pcd (0 = no downsampling)")
     .add("node.checkpoint_keyframes", &N::checkpoint_keyframes, atLeast(0), "", "keyframes between loop-closer checkpoints in live runs (0 = never)")
     .add("node.clouds_in_memory", &N::clouds_in_memory, atLeast(0), "keyframes", "keyframes whose clouds, keypoints and Scan Contexts stay in memory in live runs, older ones paged to files in the run folder (0 = all in memory)");
    return t;
  }();
  return table;
}

const ConfigTable<RelocNodeConfig>& relocNodeConfigTable() {
  using N = RelocNodeConfig;
  static const ConfigTable<N> table = [] {
    ConfigTable<N> t("reloc");
    t.add("prior_map", &N::prior_map, anyValue(), "", "map bundle folder to relocalise in (\"\" = none: map from scratch)")
     .add("mode", &N::mode, oneOf({"localise", "extend"}), "",
          "localise: the bundle stays fixed, the pose in it is published; extend: also, the loop closer's saved bundle joins the run to it")
     .nest(&N::extend, bundleExtendConfigTable());
    return t;
  }();
  return table;
}

const std::vector<std::string>& foreignConfigSections() {
  static const std::vector<std::string> sections{"sim", "lidar_driver", "pcd", "imu_csv", "eval"};
  return sections;
}

namespace {

template <class S>
void describeInto(const ConfigTable<S>& table, const S& in_force, std::map<std::string, ConfigKeyInfo>& out) {
  for (auto& info : table.describe(in_force)) out.emplace(info.key, std::move(info));  // first table wins
}

}  // namespace

std::vector<ConfigKeyInfo> pipelineConfigDescription(const Config& c) {
  std::map<std::string, ConfigKeyInfo> keys;
  describeInto(ablationConfigTable(), ablationConfigTable().read(c), keys);
  describeInto(featureConfigTable(), featureConfigFrom(c), keys);
  describeInto(scanToScanConfigTable(), scanToScanConfigFrom(c), keys);
  describeInto(initialGuessConfigTable(), initialGuessConfigFrom(c), keys);
  describeInto(wheelMotionConfigTable(), wheelMotionConfigTable().read(c), keys);
  describeInto(gyroBiasConfigTable(), gyroBiasConfigTable().read(c), keys);
  describeInto(mapperConfigTable(), mapperConfigFrom(c), keys);
  describeInto(loopCloserConfigTable(), loopCloserConfigFrom(c), keys);
  describeInto(featureNodeConfigTable(), featureNodeConfigTable().read(c), keys);
  describeInto(odometryNodeConfigTable(), odometryNodeConfigTable().read(c), keys);
  describeInto(mapperNodeConfigTable(), mapperNodeConfigTable().read(c), keys);
  describeInto(loopCloserNodeConfigTable(), loopCloserNodeConfigTable().read(c), keys);
  describeInto(mapUpdateConfigTable(), mapUpdateConfigFrom(c), keys);
  describeInto(relocaliserConfigTable(), relocaliserConfigTable().read(c), keys);
  describeInto(relocNodeConfigTable(), relocNodeConfigTable().read(c), keys);
  describeInto(inputCheckConfigTable(), inputCheckConfigTable().read(c), keys);
  std::vector<ConfigKeyInfo> out;
  for (auto& kv : keys) out.push_back(std::move(kv.second));
  return out;
}

void validatePipelineConfig(const Config& c) {
  checkKnownKeys(c, pipelineConfigDescription(Config{}), foreignConfigSections());
  pipelineConfigDescription(c);
}

}  // namespace adit::nodes
