// The feature stage's keys: one line each (key, field, allowed range, unit, doc); see core/config_table.hpp.
#include "features/feature_config.hpp"

#include <cmath>

namespace adit {
namespace {

using P = PreprocessConfig;
using D = DeskewConfig;
using L = LoamConfig;
using K = LinK3dConfig;
using R = RansacConfig;

ConfigTable<P> preprocessTable() {
  ConfigTable<P> t("features.preprocess");
  t.add("min_range", &P::min_range, atLeast(0), "m", "nearer returns (robot, housing, dust on the window) are dropped")
   .add("max_range", &P::max_range, above(0), "m", "farther returns are dropped (sparse and noisy)")
   .add("body_box_min", &P::body_box_min, anyValue(), "m", "lidar-frame box of the vehicle's own points, min corner [x, y, z]; off unless min < max on every axis")
   .add("body_box_max", &P::body_box_max, anyValue(), "m", "max corner [x, y, z] of that box")
   .add("outlier_min_neighbors", &P::outlier_min_neighbors, between(0, 50), "", "radius outlier filter: fewer neighbours within the radius and a point is dust; 0 disables")
   .add("outlier_window", &P::outlier_window, between(1, 50), "points", "points examined on each side in the point's own and the two adjacent rings")
   .add("outlier_radius", &P::outlier_radius, atLeast(0), "m", "outlier radius at zero range")
   .add("outlier_radius_per_m", &P::outlier_radius_per_m, atLeast(0), "m/m", "outlier radius growth per metre of range (beam spacing grows with range)")
   .add("outlier_max_range", &P::outlier_max_range, atLeast(0), "m", "only nearer points are tested for outliers (dust sits near the sensor)")
   .add("num_rings", &P::num_rings, between(1, 256), "", "beams assumed when a scan has no rings and no beam count")
   .add("min_elevation_deg", &P::min_elevation_deg, between(-90, 90), "deg", "elevation of the lowest beam (rings from elevation)")
   .add("max_elevation_deg", &P::max_elevation_deg, between(-90, 90), "deg", "elevation of the highest beam")
   .add("clockwise", &P::clockwise, anyValue(), "", "head spins clockwise seen from above (Velodyne, RoboSense): per-point time from azimuth");
  return t;
}

ConfigTable<D> deskewTable() {
  ConfigTable<D> t("features.deskew");
  t.add("enabled", &D::enabled, anyValue(), "", "false leaves points where they were measured")
   .add("imu_rotation_rpy_deg", &D::imu_rotation_rpy_deg, between(-360, 360), "deg", "rotation R_lidar_imu as [roll, pitch, yaw]")
   .add("table_steps", &D::table_steps, between(1, 10000), "", "poses precomputed across the sweep; points interpolate between them")
   .add("max_imu_gap_s", &D::max_imu_gap_s, atLeast(0), "s", "IMU samples must cover the sweep to within this at both ends, else the motion model is used")
   .add("max_prior_dt_s", &D::max_prior_dt_s, above(0), "s", "a motion prior spanning more than this (dropped sweeps) is ignored")
   .add("rotation_only_without_prior", &D::rotation_only_without_prior, anyValue(), "", "without a motion prior deskew the IMU rotation alone (false: leave the sweep raw for compensation downstream)");
  return t;
}

ConfigTable<L> loamTable() {
  ConfigTable<L> t("features.loam");
  t.add("half_window", &L::half_window, between(1, 50), "points", "neighbours on each side in the smoothness sum (LOAM: 5)")
   .add("sectors", &L::sectors, between(1, 360), "", "equal sectors per ring; features are picked per sector (A-LOAM: 6)")
   .add("edge_threshold", &L::edge_threshold, between(0, 1), "", "smoothness above which a point may be sharp (a 140 deg bend is 0.34)")
   .add("surf_threshold", &L::surf_threshold, between(0, 1), "", "smoothness below which a point may be flat (a 170 deg bend is 0.09)")
   .add("edge_min_offset", &L::edge_min_offset, atLeast(0), "m", "an edge point must lie this far from its neighbours' centroid (~5 range-noise sigma)")
   .add("edge_noise_factor", &L::edge_noise_factor, atLeast(0), "", "...and this many times the sweep's measured range noise; 0 disables")
   .add("noise_max_step", &L::noise_max_step, above(0), "m", "range noise is measured on point triplets with both steps shorter than this")
   .add("surf_max_offset", &L::surf_max_offset, atLeast(0), "m", "a point this close to its neighbours' centroid is flat whatever its smoothness")
   .add("max_sharp", &L::max_sharp, between(0, 10000), "per sector", "sharp points picked (A-LOAM: 2)")
   .add("max_less_sharp", &L::max_less_sharp, between(0, 10000), "per sector", "less-sharp points picked (A-LOAM: 20)")
   .add("max_flat", &L::max_flat, between(0, 10000), "per sector", "flat points picked (A-LOAM: 4)")
   .add("suppression_gap", &L::suppression_gap, atLeast(0), "m", "a picked point suppresses its window unless a larger gap separates them")
   .add("occlusion_ratio", &L::occlusion_ratio, above(0), "", "range jump (fraction of the nearer range) whose far side is occluded")
   .add("parallel_ratio", &L::parallel_ratio, above(0), "", "range change to both neighbours (fraction) of a surface nearly parallel to the beam")
   .add("max_neighbor_gap_deg", &L::max_neighbor_gap_deg, aboveUpTo(0, 180), "deg", "a larger azimuth gap between ring neighbours breaks the window")
   .add("less_flat_voxel", &L::less_flat_voxel, between(0.01, 10), "m", "voxel leaf of the less-flat points (A-LOAM: 0.2)")
   .add("less_flat_measured", &L::less_flat_measured, anyValue(), "", "a less-flat voxel keeps the measured point nearest its centre, not the centroid (A-LOAM: false)");
  return t;
}

ConfigTable<K> link3dTable() {
  ConfigTable<K> t("features.link3d");
  t.add("edge_threshold", &K::edge_threshold, between(0, 1), "", "smoothness above which a point is a LinK3D edge point")
   .add("edge_min_offset", &K::edge_min_offset, atLeast(0), "m", "noise floor of edge points, as features.loam.edge_min_offset")
   .add("max_range", &K::max_range, above(0), "m", "farther edge points are too sparse to cluster")
   .add("sectors", &K::sectors, between(1, 3600), "", "horizontal sectors edge points are grouped into (paper: 120)")
   .add("cluster_radial_tol", &K::cluster_radial_tol, above(0), "m", "a point joins a cluster whose mean horizontal range is this close")
   .add("cluster_xy_tol", &K::cluster_xy_tol, above(0), "m", "...and whose mean horizontal position is this close")
   .add("merge_radial_tol", &K::merge_radial_tol, above(0), "m", "clusters of neighbouring sectors this close in range are merged")
   .add("merge_xy_tol", &K::merge_xy_tol, above(0), "m", "...and this close in horizontal position")
   .add("min_cluster_points", &K::min_cluster_points, between(1, 100000), "points", "points a merged cluster needs to become a keypoint")
   .add("min_cluster_rings", &K::min_cluster_rings, between(1, 256), "rings", "distinct rings a merged cluster needs")
   .add("min_keypoints", &K::min_keypoints, between(0, 100000), "", "fewer keypoints flag the sweep as having too few to match")
   .add("bin_tolerance", &K::bin_tolerance, above(0), "m", "two descriptor bins agree if both non-zero and closer than this")
   .add("min_score", &K::min_score, between(1, 180), "bins", "agreeing bins a match needs (reference code: 3)");
  return t;
}

ConfigTable<R> ransacTable() {
  ConfigTable<R> t("features.ransac");
  t.add("iterations", &R::iterations, between(1, 1000000), "", "3-point hypotheses tried")
   .add("inlier_threshold", &R::inlier_threshold, above(0), "m", "a keypoint pair is an inlier if the transform brings it this close")
   .add("min_inliers", &R::min_inliers, between(3, 100000), "", "fewer inliers: no reliable transform")
   .add("min_sample_area", &R::min_sample_area, atLeast(0), "m^2", "hypotheses from a smaller (nearly collinear) triangle are skipped")
   .add("robust_scale", &R::robust_scale, above(0), "m", "Cauchy scale of the final weighted refit")
   .add("seed", &R::seed, between(0, 4294967295.0), "", "seed of the hypothesis sampler (results are deterministic)");
  return t;
}

}  // namespace

const ConfigTable<FeatureConfig>& featureConfigTable() {
  static const ConfigTable<FeatureConfig> table = [] {
    ConfigTable<FeatureConfig> t("features");
    t.add("threads", &FeatureConfig::threads, between(1, 64), "threads",
          "threads of the feature stage (same result for any count)")
     .nest(&FeatureConfig::preprocess, preprocessTable())
     .nest(&FeatureConfig::deskew, deskewTable())
     .nest(&FeatureConfig::loam, loamTable())
     .nest(&FeatureConfig::link3d, link3dTable())
     .nest(&FeatureConfig::ransac, ransacTable());
    return t;
  }();
  return table;
}

Eigen::Quaterniond rotationFromRpyDeg(const Eigen::Vector3f& rpy_deg) {
  const Eigen::Vector3f rpy = rpy_deg * static_cast<float>(M_PI / 180.0);
  return Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX());
}

FeatureConfig featureConfigFrom(const Config& c) {
  FeatureConfig f = featureConfigTable().read(c);
  f.deskew.R_lidar_imu = rotationFromRpyDeg(f.deskew.imu_rotation_rpy_deg);
  return f;
}

}  // namespace adit
