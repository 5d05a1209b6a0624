// Reads LoopCloserConfig from dotted keys "loop.*"; every default is the one documented in the headers.
#include "loop/loop_closer.hpp"

namespace adit {
namespace {

template <class T>
void read(const Config& c, const std::string& key, T& field) {
  field = c.get<T>("loop." + key, field);
}

}  // namespace

LoopCloserConfig loopCloserConfigFrom(const Config& c) {
  LoopCloserConfig k;
  read(c, "keyframe_distance", k.keyframe_distance);
  read(c, "keyframe_angle_deg", k.keyframe_angle_deg);
  read(c, "keyframe_voxel", k.keyframe_voxel);
  read(c, "level_scan_context", k.level_scan_context);

  read(c, "scan_context.max_range", k.scan_context.max_range);
  read(c, "scan_context.min_range", k.scan_context.min_range);
  read(c, "scan_context.rings", k.scan_context.rings);
  read(c, "scan_context.sectors", k.scan_context.sectors);
  read(c, "scan_context.height_offset", k.scan_context.height_offset);
  read(c, "scan_context.shift_search_radius", k.scan_context.shift_search_radius);
  read(c, "candidates", k.candidates);
  read(c, "max_scan_context_distance", k.max_scan_context_distance);
  read(c, "max_verifications", k.max_verifications);
  read(c, "exclude_recent_keyframes", k.exclude_recent_keyframes);
  read(c, "exclude_recent_seconds", k.exclude_recent_seconds);
  read(c, "cooldown_keyframes", k.cooldown_keyframes);

  LoopVerifierConfig& v = k.verifier;
  read(c, "verifier.submap_neighbors", v.submap_neighbors);
  read(c, "verifier.submap_voxel", v.submap_voxel);
  read(c, "verifier.query_voxel", v.query_voxel);
  read(c, "verifier.max_rms", v.max_rms);
  read(c, "verifier.min_inlier_ratio", v.min_inlier_ratio);
  read(c, "verifier.min_eigenvalue_ratio", v.min_eigenvalue_ratio);
  read(c, "verifier.icp.max_iterations", v.icp.max_iterations);
  read(c, "verifier.icp.coarse_correspondence_distance", v.icp.coarse_correspondence_distance);
  read(c, "verifier.icp.fine_correspondence_distance", v.icp.fine_correspondence_distance);
  read(c, "verifier.icp.inlier_residual", v.icp.inlier_residual);
  read(c, "verifier.icp.normal_neighbors", v.icp.normal_neighbors);
  read(c, "verifier.icp.max_surface_variation", v.icp.max_surface_variation);
  read(c, "verifier.icp.characteristic_length", v.icp.characteristic_length);

  read(c, "odometry_translation_sigma", k.odometry_translation_sigma);
  read(c, "odometry_rotation_sigma", k.odometry_rotation_sigma);
  read(c, "odometry_min_translation_sigma", k.odometry_min_translation_sigma);
  read(c, "odometry_min_rotation_sigma", k.odometry_min_rotation_sigma);
  read(c, "use_mapper_covariance", k.use_mapper_covariance);
  read(c, "loop_translation_sigma", k.loop_translation_sigma);
  read(c, "loop_rotation_sigma", k.loop_rotation_sigma);
  read(c, "max_odometry_chi2", k.max_odometry_chi2);
  read(c, "min_consistent_loops", k.min_consistent_loops);
  read(c, "consistency_window", k.consistency_window);
  read(c, "max_pair_chi2", k.max_pair_chi2);

  read(c, "graph.max_iterations", k.graph.max_iterations);
  read(c, "graph.loop_loss_scale", k.graph.loop_loss_scale);
  return k;
}

}  // namespace adit
