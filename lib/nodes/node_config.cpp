#include "nodes/node_config.hpp"

#include "features/feature_config.hpp"
#include "loop/loop_closer.hpp"
#include "map/map_updates.hpp"
#include "mapping/scan_to_map.hpp"
#include "odometry/initial_guess.hpp"
#include "odometry/scan_to_scan.hpp"

namespace adit::nodes {

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
     .add("forward_cloud_voxel", &N::forward_cloud_voxel, atLeast(0), "m", "voxel of the sweep forwarded on ODOM_SCAN (0 = as received)")
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
     .add("node.checkpoint_keyframes", &N::checkpoint_keyframes, atLeast(0), "", "keyframes between loop-closer checkpoints in live runs (0 = never)");
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
  describeInto(mapperConfigTable(), mapperConfigFrom(c), keys);
  describeInto(loopCloserConfigTable(), loopCloserConfigFrom(c), keys);
  describeInto(featureNodeConfigTable(), featureNodeConfigTable().read(c), keys);
  describeInto(odometryNodeConfigTable(), odometryNodeConfigTable().read(c), keys);
  describeInto(mapperNodeConfigTable(), mapperNodeConfigTable().read(c), keys);
  describeInto(loopCloserNodeConfigTable(), loopCloserNodeConfigTable().read(c), keys);
  describeInto(mapUpdateConfigTable(), mapUpdateConfigFrom(c), keys);
  std::vector<ConfigKeyInfo> out;
  for (auto& kv : keys) out.push_back(std::move(kv.second));
  return out;
}

void validatePipelineConfig(const Config& c) {
  checkKnownKeys(c, pipelineConfigDescription(Config{}), foreignConfigSections());
  pipelineConfigDescription(c);
}

}  // namespace adit::nodes
