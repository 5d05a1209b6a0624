// A map bundle: what a run saves so that later runs can start in its map (issue 18). One folder:
//   manifest.yaml    format, version, date (of the data), sensor configuration, keyframes, extent, roadway
//                    length, and the size and CRC-32 of every other file
//   map.pcd          the corrected global map
//   keyframes.bin    per keyframe: sensor time, corrected pose (map frame), compact downsampled cloud (lidar
//                    frame), Scan Context descriptor
//   pose_graph.g2o   the pose graph
//   config.yaml      every pipeline key the run used (key: value)
// Written into a temporary sibling folder that is renamed into place, so a reader sees the old bundle or the
// whole new one, never a mix. Loading checks everything and throws BundleError naming what is wrong.
#pragma once

#include "core/types.hpp"
#include "loop/compact_cloud.hpp"
#include "loop/pose_graph.hpp"
#include "loop/scan_context.hpp"

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace adit {

class LoopCloser;

class BundleError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

constexpr int kMapBundleVersion = 1;

struct BundleKeyframe {
  std::int64_t utime = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // corrected T_map_lidar
  CompactCloud cloud;                                       // downsampled, lidar frame
  ScanContext context;                                      // as the loop closer built it
};

struct BundleSummary {
  int version = 0;
  std::string created;  // ISO 8601 UTC of the newest keyframe's sensor time (not the wall clock: reproducible)
  int keyframes = 0;
  Eigen::Vector3d extent_min = Eigen::Vector3d::Zero(), extent_max = Eigen::Vector3d::Zero();  // keyframe positions
  double roadway_length_m = 0.0;  // distinct roadway driven (revisits counted once)
  double map_voxel = 0.0;
  std::map<std::string, std::string> sensor;  // the configuration keys a relocalising run must share
  struct File {
    std::uint64_t bytes = 0;
    std::uint32_t crc32 = 0;
  };
  std::map<std::string, File> files;
};

struct MapBundle {
  BundleSummary summary;
  std::vector<BundleKeyframe> keyframes;
  PoseGraph graph;
  std::vector<Eigen::Vector3f> map;            // filled when writing; loading leaves it empty (see loadMapBundle)
  std::map<std::string, std::string> config;  // every pipeline key of the run
};

// The keys of `config` that describe the sensor and the keyframe descriptors: a bundle is only usable by a run
// whose values agree (beams, elevations, Scan Context grid, keyframe voxel, levelling).
std::map<std::string, std::string> bundleSensorKeys(const std::map<std::string, std::string>& config);
// "" when `run_config` agrees with the bundle's sensor keys, else which key differs and how.
std::string bundleSensorMismatch(const BundleSummary& bundle, const std::map<std::string, std::string>& run_config);

// The bundle of a loop closer's state: keyframes at their corrected poses, graph, map (voxel map_voxel).
MapBundle bundleFrom(const LoopCloser& closer, double map_voxel, const std::map<std::string, std::string>& config);
// Distinct roadway length (m) of a keyframe path: steps ending within `revisit_radius` of a keyframe more than
// `recent` keyframes older, or of any `mapped` position (roadway an earlier session already holds), are a
// revisit and not counted.
double roadwayLength(const std::vector<Eigen::Vector3d>& positions, double revisit_radius = 3.0, int recent = 30,
                     const std::vector<Eigen::Vector3d>& mapped = {});
// The manifest's summary of these keyframes (extent, newest sensor date, sensor keys of `config`).
BundleSummary bundleSummaryOf(const std::vector<BundleKeyframe>& keyframes, double map_voxel,
                              const std::map<std::string, std::string>& config, double roadway_length_m);

// Writes the bundle folder atomically (see above); throws std::runtime_error naming what failed.
void writeMapBundle(const MapBundle& bundle, const std::string& dir);
// Reads the manifest and checks every file's presence, size and checksum (throws BundleError).
BundleSummary readBundleSummary(const std::string& dir);
// Everything but the map points (not needed to relocalise; they are checksummed): throws BundleError.
MapBundle loadMapBundle(const std::string& dir);
// The map points (map.pcd) of a bundle whose summary has been read (checksums checked): throws BundleError.
std::vector<Eigen::Vector3f> loadBundleMap(const std::string& dir);

}  // namespace adit
