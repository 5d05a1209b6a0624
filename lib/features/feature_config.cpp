#include "features/feature_config.hpp"

#include <cmath>
#include <vector>

namespace adit {
namespace {

Eigen::Vector3f vec3(const Config& c, const std::string& key, const Eigen::Vector3f& fallback) {
  const std::vector<float> v = c.getList<float>(key, {fallback.x(), fallback.y(), fallback.z()});
  if (v.size() != 3) throw std::runtime_error("config: '" + key + "' needs 3 values");
  return {v[0], v[1], v[2]};
}

Eigen::Quaterniond rpyDeg(const Config& c, const std::string& key) {
  const Eigen::Vector3f rpy = vec3(c, key, Eigen::Vector3f::Zero()) * static_cast<float>(M_PI / 180.0);
  return Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX());
}

PreprocessConfig preprocessFrom(const Config& c) {
  PreprocessConfig d;
  const std::string k = "features.preprocess.";
  d.min_range = c.get(k + "min_range", d.min_range);
  d.max_range = c.get(k + "max_range", d.max_range);
  d.body_box_min = vec3(c, k + "body_box_min", d.body_box_min);
  d.body_box_max = vec3(c, k + "body_box_max", d.body_box_max);
  d.outlier_min_neighbors = c.get(k + "outlier_min_neighbors", d.outlier_min_neighbors);
  d.outlier_window = c.get(k + "outlier_window", d.outlier_window);
  d.outlier_radius = c.get(k + "outlier_radius", d.outlier_radius);
  d.outlier_radius_per_m = c.get(k + "outlier_radius_per_m", d.outlier_radius_per_m);
  d.outlier_max_range = c.get(k + "outlier_max_range", d.outlier_max_range);
  d.num_rings = c.get(k + "num_rings", d.num_rings);
  d.min_elevation_deg = c.get(k + "min_elevation_deg", d.min_elevation_deg);
  d.max_elevation_deg = c.get(k + "max_elevation_deg", d.max_elevation_deg);
  d.clockwise = c.get(k + "clockwise", d.clockwise);
  return d;
}

DeskewConfig deskewFrom(const Config& c) {
  DeskewConfig d;
  const std::string k = "features.deskew.";
  d.enabled = c.get(k + "enabled", d.enabled);
  d.R_lidar_imu = rpyDeg(c, k + "imu_rotation_rpy_deg");
  d.table_steps = c.get(k + "table_steps", d.table_steps);
  d.max_imu_gap_s = c.get(k + "max_imu_gap_s", d.max_imu_gap_s);
  d.max_prior_dt_s = c.get(k + "max_prior_dt_s", d.max_prior_dt_s);
  return d;
}

LoamConfig loamFrom(const Config& c) {
  LoamConfig d;
  const std::string k = "features.loam.";
  d.half_window = c.get(k + "half_window", d.half_window);
  d.sectors = c.get(k + "sectors", d.sectors);
  d.edge_threshold = c.get(k + "edge_threshold", d.edge_threshold);
  d.surf_threshold = c.get(k + "surf_threshold", d.surf_threshold);
  d.edge_min_offset = c.get(k + "edge_min_offset", d.edge_min_offset);
  d.edge_noise_factor = c.get(k + "edge_noise_factor", d.edge_noise_factor);
  d.noise_max_step = c.get(k + "noise_max_step", d.noise_max_step);
  d.surf_max_offset = c.get(k + "surf_max_offset", d.surf_max_offset);
  d.max_sharp = c.get(k + "max_sharp", d.max_sharp);
  d.max_less_sharp = c.get(k + "max_less_sharp", d.max_less_sharp);
  d.max_flat = c.get(k + "max_flat", d.max_flat);
  d.suppression_gap = c.get(k + "suppression_gap", d.suppression_gap);
  d.occlusion_ratio = c.get(k + "occlusion_ratio", d.occlusion_ratio);
  d.parallel_ratio = c.get(k + "parallel_ratio", d.parallel_ratio);
  d.max_neighbor_gap_deg = c.get(k + "max_neighbor_gap_deg", d.max_neighbor_gap_deg);
  d.less_flat_voxel = c.get(k + "less_flat_voxel", d.less_flat_voxel);
  return d;
}

LinK3dConfig link3dFrom(const Config& c) {
  LinK3dConfig d;
  const std::string k = "features.link3d.";
  d.edge_threshold = c.get(k + "edge_threshold", d.edge_threshold);
  d.edge_min_offset = c.get(k + "edge_min_offset", d.edge_min_offset);
  d.max_range = c.get(k + "max_range", d.max_range);
  d.sectors = c.get(k + "sectors", d.sectors);
  d.cluster_radial_tol = c.get(k + "cluster_radial_tol", d.cluster_radial_tol);
  d.cluster_xy_tol = c.get(k + "cluster_xy_tol", d.cluster_xy_tol);
  d.merge_radial_tol = c.get(k + "merge_radial_tol", d.merge_radial_tol);
  d.merge_xy_tol = c.get(k + "merge_xy_tol", d.merge_xy_tol);
  d.min_cluster_points = c.get(k + "min_cluster_points", d.min_cluster_points);
  d.min_cluster_rings = c.get(k + "min_cluster_rings", d.min_cluster_rings);
  d.min_keypoints = c.get(k + "min_keypoints", d.min_keypoints);
  d.bin_tolerance = c.get(k + "bin_tolerance", d.bin_tolerance);
  d.min_score = c.get(k + "min_score", d.min_score);
  return d;
}

RansacConfig ransacFrom(const Config& c) {
  RansacConfig d;
  const std::string k = "features.ransac.";
  d.iterations = c.get(k + "iterations", d.iterations);
  d.inlier_threshold = c.get(k + "inlier_threshold", d.inlier_threshold);
  d.min_inliers = c.get(k + "min_inliers", d.min_inliers);
  d.robust_scale = c.get(k + "robust_scale", d.robust_scale);
  d.min_sample_area = c.get(k + "min_sample_area", d.min_sample_area);
  d.seed = c.get(k + "seed", d.seed);
  return d;
}

}  // namespace

FeatureConfig featureConfigFrom(const Config& c) {
  FeatureConfig f;
  f.preprocess = preprocessFrom(c);
  f.deskew = deskewFrom(c);
  f.loam = loamFrom(c);
  f.link3d = link3dFrom(c);
  f.ransac = ransacFrom(c);
  return f;
}

}  // namespace adit
