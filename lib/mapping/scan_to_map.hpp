// Scan-to-map refinement (A-LOAM laserMapping with an incremental local map): each sweep's edge and surface
// points are registered against corner and surface voxel maps around the robot, then inserted into them.
// The odometry pose only seeds the estimate, through the drift correction T_map_odom. Degenerate directions
// are held to the odometry prediction. Every sweep is processed; nothing is dropped.
#pragma once

#include "core/config_table.hpp"
#include "core/types.hpp"
#include "mapping/global_map.hpp"
#include "mapping/gravity.hpp"
#include "mapping/voxel_map.hpp"
#include "odometry/standstill.hpp"
#include "registration/correspondences.hpp"
#include "registration/solver.hpp"

#include <memory>
#include <optional>

namespace adit {

class MatchReuse;  // registration/match_reuse.hpp

class ChunkPool;  // core/chunk_pool.hpp

struct MapperConfig {
  RegistrationConfig registration;  // keys "mapping.<field>" (see registration.hpp)
  // Correspondence rounds per sweep (A-LOAM: 2, each with a fresh neighbour search).
  int outer_iterations = 2;
  // Resolution of edge / surface points, for both the current sweep and the map (m). A-LOAM's VLP-16 values;
  // 0.4 / 0.8 suit 64-beam data.
  double corner_resolution_m = 0.2;
  double surf_resolution_m = 0.4;
  // Resolution of the surface points a sweep registers with, where coarser than surf_resolution_m (0: that).
  // The map keeps its density for the plane fits while the queries thin: a 64-beam sweep has ~15k surface
  // points at 0.4 m, ~6k at 0.8 m (launch/sensors/hdl64.yaml: 0.8, A-LOAM's 64-beam surface resolution).
  double surf_query_resolution_m = 0.0;
  // Local-map voxel edge (m). Neighbour search looks at the 27 voxels around a point, so this is also the
  // largest neighbour distance that is searched exactly.
  double map_voxel_size_m = 1.0;
  int max_points_per_voxel = 20;
  // Neighbours per feature and their largest distance (A-LOAM: 5 within 1 m).
  int neighbours = 5;
  double max_neighbour_distance_m = 1.0;
  // Edge if largest eigenvalue > ratio * second (A-LOAM: 3); plane rejected if a neighbour is farther than
  // this from it (A-LOAM: 0.2 m).
  double line_eigen_ratio = 3.0;
  double plane_max_point_distance_m = 0.2;
  // The plane of a surface match passes through the map point nearest to the sweep point (its normal still
  // from all the neighbours), not through their centroid. On the curved walls and arches of a roadway the
  // centroid of a few map points lies off the surface, on the concave side, by an amount that changes as the
  // robot approaches the patch: a bias along the roadway (measured: the estimate runs 0.1 % short).
  bool plane_through_nearest = true;
  // A plane is rejected when its neighbours lie along one curve (the middle eigenvalue of their covariance
  // below plane_min_spread times the largest; 0: A-LOAM, never), and fitted to plane_wide_neighbours nearest
  // instead where that many within max_neighbour_distance_m span a surface (0: no second try). Five nearest
  // points of a 16-beam map are often one ring's arc: beyond a few metres its rings are farther apart than
  // its 0.4 m grid. On a flat floor the arc's plane is the floor, but on a curved wall it is the ring's own
  // plane, tilted up to 90 deg from the wall: its residual holds the sweep to where an earlier sweep's rings
  // fell. While the robot drives, later sweeps fill the map between the rings; at rest nothing does, and the
  // mapper's attitude stayed with the first sweep's while the chassis idled (0.15 deg RMS pitch and roll):
  // with exact sensors the estimate's pitch followed ~10 % of the truth's in the featureless world (58 mm at
  // the lidar), 50-75 % elsewhere. With 0.1 / 10: 12 mm; the noisy rest row of docs/measurements.md. 64 beams: 0
  // (launch/sensors/hdl64.yaml): rings 0.4 deg apart, and kitti_mini 02's APE grew 6.7 % with it.
  double plane_min_spread = 0.1;
  int plane_wide_neighbours = 10;
  // The line of an edge match passes through the map point nearest to the sweep point (its direction still
  // from all the neighbours), not through their centroid. Five edge points of a 16-beam map span up to a metre
  // of an edge that is curved, stepped or a corner of rock, and their centroid lies off the edge on one side:
  // APE of 120 s (seeds 1-3) 0.064 / 0.050 / 0.048 -> 0.040 / 0.028 / 0.031 m on roadway-loop, 0.056 / 0.046 ->
  // 0.032 / 0.025 m on roadway-straight (seeds 2, 3); 700 s of roadway-loop 0.0756 -> 0.0449 m; at rest the
  // mapper moved 6.0 -> 2.3 mm. 64 beams: false (launch/sensors/hdl64.yaml).
  bool line_through_nearest = true;
  // A sweep's points are also thinned against each other as they enter the local map (the points within a
  // resolution of an earlier point of the same sweep are dropped), not only against the sweeps before. For a
  // 16-beam sweep false: its points come thinned by their own grid, and the ~11 % the map dropped were left
  // to match a neighbour up to a resolution away on a curved wall (at rest the mapper moved 15 mm, 3.5 mm
  // without; roadway-loop APE 0.0650 -> 0.0636 m) for ~11 % more surface points in the map. 64 beams: true
  // (launch/sensors/hdl64.yaml), where the denser map changed KITTI by +-1 % for 15 % more mapping time.
  bool thin_within_sweep = false;
  // Map points farther than this from the robot are dropped (m): bounds memory on long runs. 16-beam
  // roadway returns are mostly within 50 m; KITTI needs ~80 m.
  double local_map_radius_m = 80.0;
  // Resolution of the saved global map (m) and the range of sweep points folded into it (m). The global map
  // grows with the explored surface: measured 600 cells per metre of simulated 16-beam roadway at 0.2 m / 40 m
  // (2700 at 0.1 m / 60 m); at ~50 bytes a cell a 30-minute, 2.3 km run holds ~70 MB. Far 16-beam returns
  // are sparse and noisy, hence the range limit.
  double global_map_resolution_m = 0.2;
  double global_map_max_range_m = 40.0;
  // Bound of the global map (mapping/global_map.hpp): beyond this many voxels its resolution doubles. 1.5 M
  // voxels (~85 MB) hold ~2.5 km of 16-beam roadway at 0.2 m. The mapper keeps no global map at all where
  // the loop closer's map replaces it (live, and replay with the loop closer).
  int global_map_max_voxels = 1500000;
  // Compensate sweeps that arrive raw (not deskewed) with the odometry motion before they enter the map: a
  // smeared sweep in the map misleads every later one (KITTI start-up: 0.2 m / 0.7 deg errors without).
  bool compensate_raw_sweeps = true;
  // A robot standing still reports the mean of its registrations and leaves the map as it is
  // (odometry/standstill.hpp; keys mapping.standstill.*). Measured at rest for 60 s, noisy lidar and IMU,
  // idling chassis: see docs/measurements.md, "Standing still".
  StandstillConfig standstill;
  // Each sweep's tilt is turned towards the map's down, found from the accelerometer that ODOM_SCAN carries
  // preintegrated and the mapper's own poses (gravity.hpp; keys mapping.gravity.*), so a long map does not bend.
  GravityConfig gravity;
};

// Plain A-LOAM laserMapping behaviour for the ablation: no degeneracy prior, raw sweeps enter the map as they
// are, 2 rounds of 4 iterations. (The local map stays a voxel hash: a data structure, not a behaviour.)
MapperConfig aloamMapperConfig();

// Reads "mapping.*" keys with the defaults above; with "ablation.aloam: true" the defaults are
// aloamMapperConfig()'s (explicit mapping.* keys still override them). Throws ConfigError.
MapperConfig mapperConfigFrom(const Config& c);
const ConfigTable<MapperConfig>& mapperConfigTable();

class ScanToMapMapper {
 public:
  explicit ScanToMapMapper(MapperConfig config = {});

  // Refines the sweep's pose against the local map, then adds the sweep to the maps. `odometry` is the
  // odometry estimate T_odom_lidar for f.utime. Returns T_world_lidar. Never throws; a sweep that cannot be
  // registered keeps the odometry prediction and is flagged kRegistrationFailed.
  PoseEstimate process(const FeatureSet& f, const PoseEstimate& odometry);

  // A loop closure moved the trajectory: T_corrected_uncorrected is applied to the local map and to every
  // future pose. The global map keeps points where they were registered (rebuilding it from corrected
  // keyframes is the loop closer's job).
  void applyCorrection(const Eigen::Isometry3d& T_corrected_uncorrected);

  // The global map downsampled to voxel_size (m), deterministic order: what map.pcd holds.
  std::vector<Eigen::Vector3f> globalMap(double voxel_size) const;
  // Stop building the global map (another stage owns the map): frees it; globalMap() is empty from then on.
  void dropGlobalMap();
  bool keepsGlobalMap() const { return keep_global_map_; }

  // What a restarted mapper needs to continue: the drift correction, the last odometry pose it saw and the
  // local map (the global map is the loop closer's job and is not part of it).
  struct State {
    std::int64_t utime = -1;  // last sweep; -1: none yet
    Eigen::Isometry3d T_map_odom = Eigen::Isometry3d::Identity();
    Eigen::Isometry3d previous_odometry = Eigen::Isometry3d::Identity();
    std::vector<Eigen::Vector3d> corners, surfs;
    GravityReference::State gravity;
  };
  State state() const;
  // Continues from `state`: the next sweep is registered against the restored local map.
  void restore(const State& state);

  const VoxelMap& cornerMap() const { return corner_map_; }
  const VoxelMap& surfMap() const { return surf_map_; }
  const Eigen::Isometry3d& mapFromOdometry() const { return T_map_odom_; }
  // CPU time (ms, monitoring only) of the search threads beside the caller's: negative without them.
  double helperCpuMs() const;
  // The map's down is known and the sweeps' tilt is corrected towards it (mapping.gravity).
  bool holdsTiltToGravity() const { return gravity_reference_.known() && config_.gravity.time_constant_s > 0.0; }
  int gravityRejected() const { return gravity_observer_.rejected(); }
  int gravityDisagreements() const { return gravity_reference_.disagreements(); }

 private:
  // reuse: keep a query's match from an earlier round of the same sweep while it barely moves.
  Correspondences match(const std::vector<Eigen::Vector3d>& corners, const std::vector<Eigen::Vector3d>& surfs,
                        const Eigen::Isometry3d& T_world_lidar, MatchReuse* reuse) const;
  struct Sweep {  // what the maps take from a FeatureSet
    std::int64_t utime = 0;
    bool raw = false;
    std::vector<LidarPoint> corners, surfs, cloud;
    std::vector<Eigen::Vector3d> corner_points, surf_points;  // downsampled corners / surfs (into the maps)
    std::vector<Eigen::Vector3d> surf_queries;  // surf_points at surf_query_resolution_m, if coarser
    // The surface points the sweep registers with: no copy of surf_points where the resolutions are equal.
    const std::vector<Eigen::Vector3d>& registeredSurfs() const { return surf_queries.empty() ? surf_points : surf_queries; }
  };
  struct Refinement {
    bool ok = false;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    RegistrationResult result;  // of the last round
  };
  // Correspondence rounds against the local map from the prediction (which also holds degenerate directions).
  Refinement refine(const Sweep& sweep, const Eigen::Isometry3d& predicted, int& iterations) const;
  Sweep prepare(const FeatureSet& f) const;
  void downsample(Sweep& s) const;
  void compensate(Sweep& s, const Eigen::Isometry3d& T_prev_curr, double gap_s) const;
  void addToMaps(const Sweep& s, const Eigen::Isometry3d& T_world_lidar);
  // The local map and what is kept in its frame move by T (a loop correction, the gravity's levelling).
  void moveLocalMap(const Eigen::Isometry3d& T);

  MapperConfig config_;
  VoxelMap corner_map_;
  VoxelMap surf_map_;
  GlobalMap global_map_;
  std::shared_ptr<ChunkPool> pool_;  // correspondence search threads (none: search_threads 1)
  bool keep_global_map_ = true;
  Eigen::Isometry3d T_map_odom_ = Eigen::Isometry3d::Identity();  // drift correction of the odometry
  bool corrected_ = false;  // a correction arrived since the last output (flag it once)
  bool has_previous_ = false;
  std::int64_t previous_utime_ = 0;
  Eigen::Isometry3d previous_odometry_ = Eigen::Isometry3d::Identity();
  std::optional<Sweep> pending_;  // first raw sweep, waiting for a motion estimate
  Eigen::Isometry3d pending_pose_ = Eigen::Isometry3d::Identity();
  StandstillHold standstill_;
  GravityObserver gravity_observer_;
  GravityReference gravity_reference_;
  std::optional<Eigen::Vector3d> gravity_;  // world frame, found over the sweeps so far (none: not yet, or lost)
};

}  // namespace adit
