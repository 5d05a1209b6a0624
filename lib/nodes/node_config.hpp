// Node-level keys (`<stage>.node.*`: buffers, what each process forwards and saves) and the pipeline's whole
// configuration schema: every key the four stages read, which top-level sections belong to the pipeline,
// and the validation run when a pipeline node is built or `adit config` loads a file.
//
// Section ownership. A configuration file may hold keys for several readers; each top-level section has one
// owner. The pipeline owns `features`, `odometry`, `mapping`, `loop`, `ablation` and `input`: every key there must be
// in a table (an unknown one is an error naming it, its file and the nearest known key). The sections in
// foreignConfigSections() are read by other code and skipped here: `sim` (lib/sim: adit sim / demo / bench),
// `lidar_driver` (lib/drivers: adit-lidar-bridge), `pcd` and `imu_csv` (lib/io: importers, bridges), `eval`
// (lib/eval: adit eval). Any other top-level section is an error. A new reader of the YAML files adds its
// section to foreignConfigSections().
#pragma once

#include "core/config_table.hpp"
#include "map/bundle_extend.hpp"
#include "runtime/node.hpp"

#include <map>
#include <string>
#include <vector>

namespace adit::nodes {

struct FeatureNodeConfig {
  double imu_keep_s = 0.5;       // IMU older than a sweep plus this margin is of no use to deskewing
  double max_prior_age_s = 0.3;  // an odometry pose older than this before a sweep is too stale a prior
  // FEATURES carries the sweep only thinned to this voxel: what the mapper's global map (0.1 m) and, thinned
  // again, the loop closer's keyframes need. 0 = the whole preprocessed sweep (5x the bytes).
  double map_cloud_voxel = 0.1;
};
struct OdometryNodeConfig {
  double imu_keep_s = 1.0;
  // Thinning of the sweep forwarded on ODOM_SCAN (0 = as received). The feature stage already thins it to
  // features.node.map_cloud_voxel (0.1 m): thinning it again at the same voxel changed a handful of points of a
  // 120 s map and no pose, for 1.5 % of a replay's CPU. Set it when FEATURES carries whole sweeps.
  double forward_cloud_voxel = 0.0;
  double checkpoint_period_s = 0.5;  // sensor seconds between pose checkpoints (live runs; ~200 B each)
  // After a gap in the input (a restart, a stalled stage) the pose continues at the last velocity for at most
  // this long; beyond, it stays where it was.
  double max_extrapolation_s = 5.0;
};
struct MapperNodeConfig {
  double map_voxel = 0.1;
  double forward_cloud_voxel = 0.2;  // thinning of the sweep forwarded on ODOM_MAPPED (0 = whole)
  double checkpoint_period_s = 2.0;  // sensor seconds between local-map checkpoints (live runs; 0 = on stop only)
};
struct LoopCloserNodeConfig {
  double map_voxel = 0.1;         // key "loop.map_voxel" (kept where it always was)
  int checkpoint_keyframes = 10;  // key "loop.node.checkpoint_keyframes": keyframes between checkpoints (0 = never)
  // key "loop.node.clouds_in_memory": in a live run (a run folder), the newest keyframes whose clouds, keypoints
  // and Scan Contexts stay in memory; older ones go to page files there (loop/keyframe_cloud_store.hpp,
  // loop/scan_context_database.hpp). 0 keeps everything in memory.
  int clouds_in_memory = 100;
};

// Keys "reloc.prior_map", "reloc.mode" and "reloc.extend.*": the map bundle a run relocalises in (issue 18;
// "" = none, the run maps from scratch) and what it does there. localise: the bundle stays fixed. extend: the
// run's own map (the loop closer's) is also joined to the bundle when it saves one (map/bundle_extend.hpp).
struct RelocNodeConfig {
  std::string prior_map;
  std::string mode = "localise";
  BundleExtendConfig extend;
  bool extending() const { return mode == "extend" && !prior_map.empty(); }
};

// Section `input`: the bus input checks every node applies (runtime/node.hpp InputChecks, msg/validate.hpp
// InputLimits, msg/wire_check.hpp WireLimits), the same for every stage, so one file can tighten them for a
// deployment (e.g. the IMU's real full scale) or loosen one that refuses a real sensor. Defaults are theirs.
struct InputCheckConfig {
  double max_future_s = runtime::InputChecks{}.max_future_s;
  int confirm_messages = runtime::InputChecks{}.confirm_messages;
  double max_step_periods = runtime::InputChecks{}.max_step_periods;
  int max_seq_gap = static_cast<int>(runtime::InputChecks{}.max_seq_gap);
  int max_elements = static_cast<int>(msg::WireLimits{}.max_elements);
  int max_string_bytes = static_cast<int>(msg::WireLimits{}.max_string_bytes);
  int max_text_length = static_cast<int>(msg::InputLimits{}.max_string_length);
  double max_angular_velocity = msg::InputLimits{}.max_angular_velocity;
  double max_acceleration = msg::InputLimits{}.max_acceleration;
  double max_wheel_speed = msg::InputLimits{}.max_wheel_speed;
};

const ConfigTable<InputCheckConfig>& inputCheckConfigTable();
// The input checks under `config` (section `input`).
runtime::InputChecks inputChecksFrom(const Config& config);

const ConfigTable<FeatureNodeConfig>& featureNodeConfigTable();
const ConfigTable<OdometryNodeConfig>& odometryNodeConfigTable();
const ConfigTable<MapperNodeConfig>& mapperNodeConfigTable();
const ConfigTable<LoopCloserNodeConfig>& loopCloserNodeConfigTable();
const ConfigTable<RelocNodeConfig>& relocNodeConfigTable();

// Top-level sections read by code other than the pipeline (see above).
const std::vector<std::string>& foreignConfigSections();

// Every pipeline key (sorted, each once) with the value in force under `config`, its default, type, range,
// unit and doc. Reads every table: throws ConfigError on a bad value.
std::vector<ConfigKeyInfo> pipelineConfigDescription(const Config& config);

// Unknown keys (see section ownership) and bad values: throws ConfigError with one line naming the key,
// the value, the file and what is allowed.
void validatePipelineConfig(const Config& config);

}  // namespace adit::nodes
