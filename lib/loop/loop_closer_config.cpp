// The loop closer's keys "loop.*": one line each (key, field, allowed range, unit, doc); see core/config_table.hpp.
#include "loop/loop_closer.hpp"

namespace adit {
namespace {

ConfigTable<ScanContextConfig> scanContextTable() {
  using C = ScanContextConfig;
  ConfigTable<C> t("loop.scan_context");
  t.add("max_range", &C::max_range, above(0), "m", "radial extent of the polar grid")
   .add("min_range", &C::min_range, atLeast(0), "m", "nearer points (robot, mount) are ignored")
   .add("rings", &C::rings, between(1, 1000), "", "annuli over [0, max_range)")
   .add("sectors", &C::sectors, between(1, 3600), "", "azimuth sectors, also the yaw resolution of a match")
   .add("height_offset", &C::height_offset, anyValue(), "m", "added to point heights so occupied bins are > 0")
   .add("shift_search_radius", &C::shift_search_radius, between(0, 1800), "sectors", "half-width of the fine column-shift search");
  return t;
}

ConfigTable<LoopVerifierConfig> verifierTable() {
  using V = LoopVerifierConfig;
  using I = IcpConfig;
  ConfigTable<I> icp("loop.verifier.icp");
  icp.add("max_iterations", &I::max_iterations, between(1, 1000), "", "Gauss-Newton iterations per ICP phase")
     .add("coarse_correspondence_distance", &I::coarse_correspondence_distance, above(0), "m", "correspondence gate of the coarse phase")
     .add("fine_correspondence_distance", &I::fine_correspondence_distance, above(0), "m", "correspondence gate of the fine phase")
     .add("inlier_residual", &I::inlier_residual, above(0), "m", "point-to-plane residual below which a point is an inlier")
     .add("normal_neighbors", &I::normal_neighbors, between(3, 1000), "points", "neighbours per target normal")
     .add("max_surface_variation", &I::max_surface_variation, between(0, 1), "", "largest surface variation of a planar target point");
  ConfigTable<V> t("loop.verifier");
  t.add("submap_neighbors", &V::submap_neighbors, between(0, 1000), "keyframes", "keyframes each side of the candidate merged into its submap")
   .add("submap_voxel", &V::submap_voxel, between(0.01, 100), "m", "voxel of the submap (ICP target)")
   .add("query_voxel", &V::query_voxel, between(0.01, 100), "m", "voxel of the query cloud (ICP source)")
   .add("max_rms", &V::max_rms, above(0), "m", "largest RMS point-to-plane residual of an accepted fit")
   .add("min_inlier_ratio", &V::min_inlier_ratio, between(0, 1), "", "smallest share of query points that are inliers")
   .add("min_eigenvalue_ratio", &V::min_eigenvalue_ratio, between(0, 1), "", "smallest / largest eigenvalue of the fit's translation information: below, a direction is unconstrained")
   .add("max_rotation_sigma", &V::max_rotation_sigma, above(0), "rad", "standard deviation of the least constrained rotation of a fit at its residual: above, unconstrained")
   .nest(&V::icp, icp);
  return t;
}

ConfigTable<KeypointSeedConfig> keypointTable() {
  using P = KeypointSeedConfig;
  ConfigTable<P> t("loop.keypoints");
  t.add("use", &P::use, anyValue(), "", "seed and check verification with the keyframes' LinK3D keypoints (FEATURES)")
   .add("bin_tolerance", &P::bin_tolerance, above(0), "m", "two descriptor bins agree when both are set and this close")
   .add("min_score", &P::min_score, between(1, 180), "bins", "agreeing bins a keypoint match needs")
   .add("inlier_threshold", &P::inlier_threshold, above(0), "m", "a matched keypoint pair agrees with a transform within this distance")
   .add("min_inliers", &P::min_inliers, between(3, 10000), "keypoints", "query keypoints that must agree for a seed")
   .add("ransac_iterations", &P::ransac_iterations, between(1, 100000), "", "3-point hypotheses tried")
   .add("agree_translation", &P::agree_translation, above(0), "m", "a seed or fit this close to another is the same alignment")
   .add("agree_rotation_deg", &P::agree_rotation_deg, above(0), "deg", "same for rotation");
  return t;
}

ConfigTable<PoseGraphConfig> graphTable() {
  using G = PoseGraphConfig;
  ConfigTable<G> t("loop.graph");
  t.add("max_iterations", &G::max_iterations, between(1, 10000), "", "Levenberg-Marquardt iterations per optimisation")
   .add("loop_loss_scale", &G::loop_loss_scale, above(0), "sigma", "Cauchy scale of loop edges in loop standard deviations");
  return t;
}

}  // namespace

const ConfigTable<LoopCloserConfig>& loopCloserConfigTable() {
  using K = LoopCloserConfig;
  static const ConfigTable<K> table = [] {
    ConfigTable<K> t("loop");
    t.add("keyframe_distance", &K::keyframe_distance, above(0), "m", "mapped motion between keyframes")
     .add("keyframe_angle_deg", &K::keyframe_angle_deg, above(0), "deg", "mapped rotation between keyframes")
     .add("keyframe_voxel", &K::keyframe_voxel, between(0.01, 100), "m", "voxel of the cloud kept per keyframe")
     .add("keyframe_cloud_step", &K::keyframe_cloud_step, between(0.0001, 1), "m", "quantisation step of the kept keyframe clouds (int16 counts)")
     .add("level_scan_context", &K::level_scan_context, anyValue(), "", "build Scan Context in a gravity-levelled frame")
     .nest(&K::scan_context, scanContextTable())
     .add("candidates", &K::candidates, between(1, 1000), "", "ring-key neighbours ranked per query")
     .add("max_scan_context_distance", &K::max_scan_context_distance, between(0, 1), "", "candidates below this distance are verified")
     .add("max_verifications", &K::max_verifications, between(0, 1000), "", "best candidates verified by ICP per keyframe")
     .add("exclude_recent_keyframes", &K::exclude_recent_keyframes, between(0, 1000000), "keyframes", "never match the newest N keyframes")
     .add("exclude_recent_seconds", &K::exclude_recent_seconds, atLeast(0), "s", "nor those from the last T seconds")
     .add("cooldown_keyframes", &K::cooldown_keyframes, between(0, 1000000), "keyframes", "after an accepted loop, skip detection this long")
     .add("revisit_distance", &K::revisit_distance, atLeast(0), "m", "a keyframe this close to an older one, on a trajectory a recent loop ties to it, keeps only its graph node (0: off)")
     .add("revisit_trust_keyframes", &K::revisit_trust_keyframes, between(0, 1000000), "keyframes", "how recent that loop must be")
     .add("retire_after_keyframes", &K::retire_after_keyframes, between(0, 1000000), "keyframes", "a keyframe without a cloud older than the newest N is merged out of the pose graph (0: never; at least one more than the keyframe windows)")
     .add("retire_batch", &K::retire_batch, between(1, 1000000), "keyframes", "keyframes merged out at a time")
     .add("apply_delay_s", &K::apply_delay_s, between(0, 3600), "s", "a loop job's outcome is applied at the first sweep this much later (0: same sweep)")
     .add("worker_thread", &K::worker_thread, anyValue(), "", "verify and optimise on a worker thread (same results either way)")
     .nest(&K::verifier, verifierTable())
     .nest(&K::keypoints, keypointTable())
     .add("partial_loops", &K::partial_loops, anyValue(), "", "a fit free along one translation only joins the graph as a partial loop")
     .add("partial_loop_axis_sigma", &K::partial_loop_axis_sigma, above(1), "m", "a partial loop's standard deviation along its free axis")
     .add("partial_loop_max_axis_offset", &K::partial_loop_max_axis_offset, above(0), "m", "the graph must put a partial loop's keyframes this close along its free axis")
     .add("odometry_translation_sigma", &K::odometry_translation_sigma, above(0), "m/sqrt(m)", "odometry step noise added per sqrt of metres travelled")
     .add("odometry_rotation_sigma", &K::odometry_rotation_sigma, above(0), "rad/sqrt(m)", "same for rotation")
     .add("odometry_min_translation_sigma", &K::odometry_min_translation_sigma, above(0), "m", "floor of the step noise per keyframe step")
     .add("odometry_min_rotation_sigma", &K::odometry_min_rotation_sigma, above(0), "rad", "same for rotation")
     .add("use_mapper_covariance", &K::use_mapper_covariance, anyValue(), "", "add the mapper's per-sweep covariances of the step")
     .add("loop_translation_sigma", &K::loop_translation_sigma, above(0), "m", "noise of a verified loop measurement")
     .add("loop_rotation_sigma", &K::loop_rotation_sigma, above(0), "rad", "same for rotation")
     .add("max_odometry_chi2", &K::max_odometry_chi2, above(0), "", "Mahalanobis gate of a loop against the odometry (6 dof; 22.46 = 99.9 %)")
     .add("min_consistent_loops", &K::min_consistent_loops, between(1, 100), "", "mutually consistent loops needed (2: never trust one match)")
     .add("consistency_window", &K::consistency_window, between(0, 1000000), "keyframes", "window in which loops must agree")
     .add("max_pair_chi2", &K::max_pair_chi2, above(0), "", "pairwise consistency gate (chi-square, 6 dof)")
     .nest(&K::graph, graphTable());
    return t;
  }();
  return table;
}

LoopCloserConfig loopCloserConfigFrom(const Config& c) { return loopCloserConfigTable().read(c); }

}  // namespace adit
