#include "mapping/scan_to_map.hpp"

#include "core/chunk_pool.hpp"
#include "mapping/downsample.hpp"
#include "registration/feature_fit.hpp"
#include "registration/match_reuse.hpp"
#include "odometry/motion_compensation.hpp"
#include "registration/parallel_matching.hpp"
#include "registration/pose_increment.hpp"
#include "odometry/scan_to_scan.hpp"

namespace adit {
namespace {

std::vector<Eigen::Vector3d> toDouble(const std::vector<LidarPoint>& points) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (const LidarPoint& p : points) out.push_back(p.p.cast<double>());
  return out;
}

std::vector<Eigen::Vector3d> transformed(const std::vector<Eigen::Vector3d>& points, const Eigen::Isometry3d& T) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(T * p);
  return out;
}

}  // namespace

MapperConfig aloamMapperConfig() {
  MapperConfig m;
  m.registration.degeneracy_prior = false;
  m.compensate_raw_sweeps = false;
  m.registration.max_solver_iterations = 4;
  m.registration.reuse_match_distance_m = 0.0;  // A-LOAM searches every round afresh
  m.plane_through_nearest = false;
  m.plane_min_spread = 0.0;
  m.plane_wide_neighbours = 0;
  m.line_through_nearest = false;
  m.thin_within_sweep = true;
  m.standstill.window_sweeps = 0;  // every registration is the pose
  m.gravity.time_constant_s = 0.0;  // A-LOAM's mapper knows no IMU
  return m;
}

const ConfigTable<MapperConfig>& mapperConfigTable() {
  using M = MapperConfig;
  static const ConfigTable<M> table = [] {
    ConfigTable<M> t("mapping");
    t.nest(&M::registration, registrationConfigTable("mapping"))
     .nest(&M::standstill, standstillConfigTable("mapping.standstill"))
     .nest(&M::gravity, gravityConfigTable("mapping.gravity"))
     .add("outer_iterations", &M::outer_iterations, between(1, 100), "", "correspondence rounds per sweep (A-LOAM: 2)")
     .add("corner_resolution_m", &M::corner_resolution_m, between(0.01, 10), "m", "resolution of edge points in the sweep and the map")
     .add("surf_resolution_m", &M::surf_resolution_m, between(0.01, 10), "m", "resolution of surface points in the sweep and the map")
     .add("surf_query_resolution_m", &M::surf_query_resolution_m, between(0, 10), "m", "coarser resolution of the surface points a sweep registers with (0: surf_resolution_m)")
     .add("map_voxel_size_m", &M::map_voxel_size_m, between(0.05, 100), "m", "local-map voxel edge, also the largest exact neighbour-search radius")
     .add("max_points_per_voxel", &M::max_points_per_voxel, between(1, 100000), "points", "density bound of a local-map voxel")
     .add("neighbours", &M::neighbours, between(3, 100), "points", "neighbours per feature (A-LOAM: 5)")
     .add("max_neighbour_distance_m", &M::max_neighbour_distance_m, above(0), "m", "farthest neighbour accepted (A-LOAM: 1)")
     .add("line_eigen_ratio", &M::line_eigen_ratio, atLeast(1), "", "edge if the largest eigenvalue exceeds ratio * the second (A-LOAM: 3)")
     .add("plane_max_point_distance_m", &M::plane_max_point_distance_m, above(0), "m", "a plane is rejected if a neighbour is farther (A-LOAM: 0.2)")
     .add("plane_through_nearest", &M::plane_through_nearest, anyValue(), "", "a surface match's plane passes through the nearest map point, not the neighbours' centroid (A-LOAM: false)")
     .add("plane_min_spread", &M::plane_min_spread, between(0, 1), "", "a plane is rejected if its neighbours lie along one curve: middle eigenvalue below this times the largest (a ring's arc; A-LOAM: 0)")
     .add("plane_wide_neighbours", &M::plane_wide_neighbours, between(0, 100), "points", "a rejected plane is fitted again to this many nearest (0: not; A-LOAM: 0)")
     .add("line_through_nearest", &M::line_through_nearest, anyValue(), "", "an edge match's line passes through the nearest map point, not the neighbours' centroid (A-LOAM: false)")
     .add("thin_within_sweep", &M::thin_within_sweep, anyValue(), "", "a sweep's points are also thinned against each other as they enter the local map, not only against earlier sweeps (A-LOAM; 64 beams)")
     .add("local_map_radius_m", &M::local_map_radius_m, above(0), "m", "map points farther from the robot are dropped (bounds memory)")
     .add("global_map_resolution_m", &M::global_map_resolution_m, between(0.01, 100), "m", "resolution of the saved global map")
     .add("global_map_max_range_m", &M::global_map_max_range_m, above(0), "m", "range of the sweep points folded into the global map")
     .add("global_map_max_voxels", &M::global_map_max_voxels, between(0, 1000000000), "voxels", "bound of the global map: beyond it its resolution doubles (0: unbounded)")
     .add("compensate_raw_sweeps", &M::compensate_raw_sweeps, anyValue(), "", "compensate raw sweeps with the odometry motion before they enter the map");
    return t;
  }();
  return table;
}

MapperConfig mapperConfigFrom(const Config& c) {
  const bool aloam = ablationConfigTable().read(c).aloam;
  return mapperConfigTable().read(c, aloam ? aloamMapperConfig() : MapperConfig{});
}

ScanToMapMapper::ScanToMapMapper(MapperConfig config)
    : config_(std::move(config)),
      corner_map_(config_.map_voxel_size_m, config_.corner_resolution_m, config_.max_points_per_voxel),
      surf_map_(config_.map_voxel_size_m, config_.surf_resolution_m, config_.max_points_per_voxel),
      global_map_(config_.global_map_resolution_m, static_cast<std::size_t>(config_.global_map_max_voxels)),
      pool_(config_.registration.search_threads > 1 ? std::make_shared<ChunkPool>(config_.registration.search_threads)
                                                    : nullptr),
      standstill_(config_.standstill),
      gravity_observer_(config_.gravity),
      gravity_reference_(config_.gravity) {}

double ScanToMapMapper::helperCpuMs() const { return pool_ ? pool_->workerCpuMs() : -1.0; }

Correspondences ScanToMapMapper::match(const std::vector<Eigen::Vector3d>& corners,
                                       const std::vector<Eigen::Vector3d>& surfs, const Eigen::Isometry3d& T,
                                       MatchReuse* reuse) const {
  const int k = std::max(3, config_.neighbours);
  const auto add_line = [&](std::size_t i, std::vector<LineMatch>& lines) {
    const auto search = [&](const Eigen::Vector3d& q) -> std::optional<LineMatch> {
      thread_local std::vector<Eigen::Vector3d> near;
      corner_map_.nearest(q, k, config_.max_neighbour_distance_m, near);
      if (static_cast<int>(near.size()) < k) return std::nullopt;
      const auto line = fitLine(near, config_.line_eigen_ratio);
      if (!line) return std::nullopt;
      // VoxelMap::nearest lists the neighbours nearest first.
      return LineMatch{corners[i], config_.line_through_nearest ? near.front() : line->centroid, line->direction};
    };
    addMatch(reuse, i, T * corners[i], lines, search);
  };
  const auto add_plane = [&](std::size_t i, std::vector<PlaneMatch>& planes) {
    const auto search = [&](const Eigen::Vector3d& q) -> std::optional<PlaneMatch> {
      thread_local std::vector<Eigen::Vector3d> near;
      surf_map_.nearest(q, k, config_.max_neighbour_distance_m, near);
      if (static_cast<int>(near.size()) < k) return std::nullopt;
      auto plane = fitPlane(near, config_.plane_max_point_distance_m, config_.plane_min_spread);
      if (!plane && config_.plane_wide_neighbours > k) {  // one ring's arc, perhaps: look wider
        thread_local std::vector<Eigen::Vector3d> wide;
        surf_map_.nearest(q, config_.plane_wide_neighbours, config_.max_neighbour_distance_m, wide);
        plane = fitPlane(wide, config_.plane_max_point_distance_m, config_.plane_min_spread);
      }
      if (!plane) return std::nullopt;
      // VoxelMap::nearest lists the neighbours nearest first.
      const double offset = config_.plane_through_nearest ? -plane->normal.dot(near.front()) : plane->offset;
      return PlaneMatch{surfs[i], plane->normal, offset};
    };
    addMatch(reuse, i, T * surfs[i], planes, search);
  };
  return matchInChunks(pool_.get(), corners.size(), surfs.size(), add_line, add_plane);
}

ScanToMapMapper::Sweep ScanToMapMapper::prepare(const FeatureSet& f) const {
  Sweep s;
  s.utime = f.utime;
  s.raw = !f.cloud.deskewed;
  s.corners = f.corner_less_sharp;
  s.surfs = f.surf_less_flat;
  if (keep_global_map_) s.cloud = f.cloud.points;  // only the global map takes the whole cloud
  downsample(s);
  return s;
}

void ScanToMapMapper::downsample(Sweep& s) const {
  s.corner_points = voxelDownsample(toDouble(s.corners), config_.corner_resolution_m);
  s.surf_points = voxelDownsample(toDouble(s.surfs), config_.surf_resolution_m);
  s.surf_queries.clear();
  if (config_.surf_query_resolution_m > config_.surf_resolution_m)
    s.surf_queries = voxelDownsample(s.surf_points, config_.surf_query_resolution_m);
}

void ScanToMapMapper::compensate(Sweep& s, const Eigen::Isometry3d& T_prev_curr, double gap_s) const {
  for (auto* v : {&s.corners, &s.surfs, &s.cloud}) compensateMotion(*v, T_prev_curr, gap_s);
  s.raw = false;
  downsample(s);
}

void ScanToMapMapper::addToMaps(const Sweep& s, const Eigen::Isometry3d& T) {
  corner_map_.insert(transformed(s.corner_points, T), config_.thin_within_sweep);
  surf_map_.insert(transformed(s.surf_points, T), config_.thin_within_sweep);
  corner_map_.removeFarFrom(T.translation(), config_.local_map_radius_m);
  surf_map_.removeFarFrom(T.translation(), config_.local_map_radius_m);
  if (!keep_global_map_) return;
  std::vector<Eigen::Vector3f> cloud;
  cloud.reserve(s.cloud.size());
  for (const LidarPoint& p : s.cloud) cloud.push_back(p.p);
  global_map_.insert(cloud, T, config_.global_map_max_range_m);
}

ScanToMapMapper::Refinement ScanToMapMapper::refine(const Sweep& sweep, const Eigen::Isometry3d& predicted,
                                                     int& iterations) const {
  Refinement out;
  out.pose = predicted;
  const std::vector<Eigen::Vector3d>& surfs = sweep.registeredSurfs();
  MatchReuse reuse(sweep.corner_points.size(), surfs.size(), config_.registration.reuse_match_distance_m);
  for (int round = 0; round < std::max(1, config_.outer_iterations); ++round) {
    out.result = registerStep(match(sweep.corner_points, surfs, out.pose, &reuse), out.pose, predicted,
                              config_.registration);
    iterations += out.result.iterations;
    if (!(out.ok = out.result.ok)) break;
    const bool converged = hasConverged(out.pose, out.result.pose);
    out.pose = out.result.pose;
    if (converged) break;
  }
  return out;
}

PoseEstimate ScanToMapMapper::process(const FeatureSet& f, const PoseEstimate& odometry) {
  PoseEstimate out;
  out.utime = f.utime;
  if (corrected_) out.flags |= PoseEstimate::kLoopCorrected;
  corrected_ = false;
  const Eigen::Isometry3d odom = isFinitePose(odometry.pose) ? odometry.pose : Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d predicted = T_map_odom_ * odom;

  // Raw (not deskewed) sweeps are compensated with the odometry's motion since the previous sweep; the very
  // first one waits for that motion and enters the map when the second sweep arrives.
  Sweep sweep = prepare(f);
  const double gap_s = toSeconds(f.utime - previous_utime_);
  const bool have_motion = has_previous_ && gap_s > 0;
  const Eigen::Isometry3d motion = previous_odometry_.inverse() * odom;
  if (config_.compensate_raw_sweeps && sweep.raw && have_motion) compensate(sweep, motion, gap_s);
  if (pending_) {
    if (have_motion) compensate(*pending_, motion, gap_s);
    addToMaps(*pending_, pending_pose_);
    pending_.reset();
  }

  const bool first = !has_previous_;  // nothing to register against yet (later, an empty map is a failure)
  Eigen::Isometry3d T = predicted;
  if (!first) {
    const Refinement r = refine(sweep, predicted, out.iterations);
    if (r.ok) {
      T = r.pose;
      reportRegistration(r.result, config_.registration, out);
    } else {
      out.flags |= PoseEstimate::kRegistrationFailed;
    }
  }
  const bool registered = !first && !(out.flags & PoseEstimate::kRegistrationFailed);
  if (!registered) out.covariance = odometry.covariance;
  // The map's tilt away from gravity: the local map and this sweep turn together, so registration does not
  // pull the sweep back to the tilt the map had (gravity.hpp).
  if (const auto level = registered ? gravity_reference_.levelling(gravity_, T, f.utime) : std::nullopt) {
    moveLocalMap(*level);
    T = *level * T;
  }
  // The drift correction follows the registration, held or not: it seeds the next sweep.
  T_map_odom_ = T * odom.inverse();
  out.pose = T;
  if (registered) {
    gravity_ = gravity_observer_.add(f.utime, T, odometry.specific_force);
  } else {  // a pose that is only the odometry's prediction starts the gravity's window again
    gravity_observer_.reset();
    gravity_.reset();
  }
  if (gravity_) {
    gravity_reference_.observe(*gravity_, T);
    out.gravity = T.linear().transpose() * *gravity_;
  }
  if (registered) {
    out.pose = standstill_.update(f.utime, T);
    if (standstill_.holding()) out.flags |= PoseEstimate::kStandingStill;
  } else {
    standstill_.reset();
  }
  if (config_.compensate_raw_sweeps && sweep.raw && !have_motion) {
    pending_ = std::move(sweep);
    pending_pose_ = T;
  } else if (!standstill_.holding()) {
    addToMaps(sweep, T);
  }
  has_previous_ = true;
  previous_utime_ = f.utime;
  previous_odometry_ = odom;
  return out;
}

void ScanToMapMapper::applyCorrection(const Eigen::Isometry3d& T_corrected_uncorrected) {
  if (!isFinitePose(T_corrected_uncorrected)) return;
  T_map_odom_ = T_corrected_uncorrected * T_map_odom_;
  moveLocalMap(T_corrected_uncorrected);
  corrected_ = true;
}

void ScanToMapMapper::moveLocalMap(const Eigen::Isometry3d& T) {
  corner_map_.transform(T);
  surf_map_.transform(T);
  pending_pose_ = T * pending_pose_;
  standstill_.applyCorrection(T);
  gravity_observer_.applyCorrection(T);
  if (gravity_) gravity_ = T.linear() * *gravity_;
}

ScanToMapMapper::State ScanToMapMapper::state() const {
  State s;
  s.utime = has_previous_ ? previous_utime_ : -1;
  s.T_map_odom = T_map_odom_;
  s.previous_odometry = previous_odometry_;
  s.corners = corner_map_.points();
  s.surfs = surf_map_.points();
  s.gravity = gravity_reference_.state();
  return s;
}

void ScanToMapMapper::restore(const State& s) {
  const bool keep_global_map = keep_global_map_;
  *this = ScanToMapMapper(config_);
  if (!keep_global_map) dropGlobalMap();
  T_map_odom_ = s.T_map_odom;
  previous_odometry_ = s.previous_odometry;
  has_previous_ = s.utime >= 0;
  previous_utime_ = s.utime;
  corner_map_.insert(s.corners);
  surf_map_.insert(s.surfs);
  gravity_reference_.restore(s.gravity);
}

std::vector<Eigen::Vector3f> ScanToMapMapper::globalMap(double voxel_size) const {
  return global_map_.points(voxel_size);
}

void ScanToMapMapper::dropGlobalMap() {
  keep_global_map_ = false;
  global_map_ = GlobalMap(config_.global_map_resolution_m);
}

}  // namespace adit
