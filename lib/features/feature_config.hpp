// Configuration of the feature stage (preprocessing, deskew, LOAM features, LinK3D), with documented defaults.
// Every field can be set from the YAML config through the dotted key named in its comment; the keys, ranges
// and one-line docs are in featureConfigTable() (feature_config.cpp). Defaults are tuned for 16-beam spinning lidars (VLP-16 / RS-16) in roadways.
#pragma once

#include "core/config_table.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>

namespace adit {

struct PreprocessConfig {
  // features.preprocess.min_range (m): nearer returns hit the robot, the housing or dust on the window.
  float min_range = 0.5f;
  // features.preprocess.max_range (m): farther returns are sparse and noisy; roadways are rarely wider.
  float max_range = 100.0f;
  // features.preprocess.body_box_min / body_box_max ([x, y, z], m, lidar frame): points inside this box
  // belong to the vehicle. Disabled unless min < max on every axis (default: disabled).
  Eigen::Vector3f body_box_min = Eigen::Vector3f::Zero();
  Eigen::Vector3f body_box_max = Eigen::Vector3f::Zero();

  // Radius outlier filter (dust, water drops). A point is tested against its neighbours along its own ring
  // and the two adjacent rings (window of outlier_window points each side, which is where a real surface
  // point's nearest neighbours lie) and removed if fewer than outlier_min_neighbors lie within the radius.
  // features.preprocess.outlier_min_neighbors: 0 disables the filter. 2 keeps thin poles and cables
  // (one neighbour above or below, one beside) and drops isolated returns.
  int outlier_min_neighbors = 2;
  // features.preprocess.outlier_window: points examined on each side in each ring.
  int outlier_window = 3;
  // features.preprocess.outlier_radius (m) at zero range, plus outlier_radius_per_m per metre of range:
  // beam spacing grows linearly with range (2 deg ring spacing of a VLP-16 = 0.035 m per m).
  float outlier_radius = 0.2f;
  float outlier_radius_per_m = 0.05f;
  // features.preprocess.outlier_max_range (m): only nearer points are tested; dust sits near the sensor
  // and far points are legitimately sparse.
  float outlier_max_range = 20.0f;

  // Rings when the scan has none (has_ring false): uniform elevation bins.
  // features.preprocess.num_rings: beams assumed (used only when the scan says num_beams = 0).
  int num_rings = 16;
  // features.preprocess.min_elevation_deg / max_elevation_deg: elevation of the lowest / highest beam
  // (VLP-16 and RS-16: -15 .. +15 deg).
  float min_elevation_deg = -15.0f;
  float max_elevation_deg = 15.0f;

  // Per-point time when the scan has none (has_time false), for a spinning lidar: the first point of the
  // input array was fired first, and time grows linearly with the azimuth swept since then.
  // features.preprocess.clockwise: true if the head spins clockwise seen from above (azimuth atan2(y, x)
  // decreases with time), as Velodyne and RoboSense heads do.
  bool clockwise = true;
};

struct DeskewConfig {
  // features.deskew.enabled: false leaves points where they were measured.
  bool enabled = true;
  // features.deskew.imu_rotation_rpy_deg ([roll, pitch, yaw], deg): rotation R_lidar_imu taking IMU-frame
  // vectors into the lidar frame. Identity by default (IMU mounted aligned with the lidar). featureConfigFrom
  // sets R_lidar_imu from imu_rotation_rpy_deg.
  Eigen::Vector3f imu_rotation_rpy_deg = Eigen::Vector3f::Zero();
  Eigen::Quaterniond R_lidar_imu = Eigen::Quaterniond::Identity();
  // features.deskew.table_steps: poses precomputed across the sweep; points interpolate between them.
  // 32 steps = 3 ms apart at 10 Hz, far finer than the motion changes.
  int table_steps = 32;
  // features.deskew.max_imu_gap_s (s): IMU samples must cover the sweep to within this at both ends,
  // otherwise the IMU is not used (falls back to the motion model).
  double max_imu_gap_s = 0.02;
  // features.deskew.max_prior_dt_s (s): a motion prior spanning more than this (dropped sweeps) is ignored.
  double max_prior_dt_s = 0.5;
  // features.deskew.rotation_only_without_prior: with no motion prior (the first two sweeps, after a gap)
  // deskew the IMU's rotation alone. false (default) leaves such a sweep raw: a rotation-only deskew assumes
  // no translation, wrong when the vehicle already moves (a 1.5 m/s start erred by 6.5 cm on the first
  // deskewed pair), while a raw sweep is compensated downstream (odometry, mapper) with the motion estimated.
  bool rotation_only_without_prior = false;
};

struct LoamConfig {
  // features.loam.half_window: neighbours on each side in the smoothness sum (LOAM: 5).
  int half_window = 5;
  // features.loam.sectors: each ring is split into this many equal sectors, features picked per sector
  // so they spread around the sweep (A-LOAM: 6).
  int sectors = 6;
  // Smoothness is dimensionless (see smoothness.hpp): |sum_j (p_j - p_i)| over the neighbours' path length
  // from p_i. It is 0 on a straight scan line, cos(a/2) at a corner of interior angle a (0.71 at 90 deg),
  // and does not depend on range or angular resolution.
  // features.loam.edge_threshold: above this a point may be sharp / less sharp (a 140 deg bend is 0.34).
  float edge_threshold = 0.3f;
  // features.loam.surf_threshold: below this a point may be flat (a 170 deg bend is 0.09).
  float surf_threshold = 0.1f;
  // features.loam.edge_min_offset (m): an edge point must also lie this far from its neighbours' centroid
  // (PointScores::offset). Range noise alone moves a point by about its sigma, and a sweep has tens of
  // thousands of tries: set ~5 sigma (1 cm range noise, VLP-16 class: 0.05; with 0.03, as A-LOAM's
  // threshold, most sharp picks in a noisy box room were noise). A 90 deg corner sits ~2 beam spacings
  // off, so on a VLP-16 corners count from ~7 m; nearer, the noise hides them anyway.
  float edge_min_offset = 0.05f;
  // features.loam.edge_noise_factor: the offset must also exceed this many times the sweep's measured range
  // noise (PointScores::noise), so the floor follows the sensor actually used. A noise-only offset is
  // ~1.05 sigma: at 5 sigma a 30k-point sweep has well under one false edge, at 2.5 sigma (0.05 m with the
  // 2 cm simulated VLP-16) ~180 per sweep appeared on the smooth walls beside the sensor, slid with it and
  // held scan matching at zero motion along a featureless roadway. 0 disables.
  float edge_noise_factor = 5.0f;
  // features.loam.noise_max_step (m): the noise is measured on triplets of consecutive ring points whose two
  // steps are both shorter than this (dense enough that the surface's bend is below the noise).
  float noise_max_step = 0.1f;
  // features.loam.surf_max_offset (m): a point this close to its neighbours' centroid is flat whatever its
  // ratio: near the sensor the beam spacing is below the noise and the ratio only measures noise.
  float surf_max_offset = 0.01f;
  // features.loam.max_sharp / max_less_sharp / max_flat: per sector (A-LOAM: 2 / 20 / 4).
  int max_sharp = 2;
  int max_less_sharp = 20;
  int max_flat = 4;
  // features.loam.suppression_gap (m): after picking a point, neighbours within half_window are suppressed
  // unless a gap larger than this separates them (they then lie on another object).
  float suppression_gap = 0.2f;
  // features.loam.occlusion_ratio: adjacent points whose ranges differ by more than this fraction of the
  // nearer range form a depth jump; the far side is an occluded edge that moves with the viewpoint.
  float occlusion_ratio = 0.1f;
  // features.loam.parallel_ratio: a point whose range differs from both neighbours by more than this
  // fraction lies on a surface nearly parallel to the beam; its position along the surface is unreliable.
  float parallel_ratio = 0.02f;
  // features.loam.max_neighbor_gap_deg (deg): a larger azimuth gap between consecutive points of a ring
  // (missing returns) breaks the neighbourhood; windows spanning it are not evaluated.
  float max_neighbor_gap_deg = 2.0f;
  // features.loam.less_flat_voxel (m): less-flat points are voxel downsampled with this leaf (A-LOAM: 0.2).
  float less_flat_voxel = 0.2f;
  // features.loam.less_flat_measured: each voxel keeps the measured point nearest its centre, and every flat
  // point is kept, instead of the points' centroid (A-LOAM). A centroid lies off a curved wall or between two
  // rings at different depths (up to 9 cm on a simulated roadway): with exact sensors at rest, scan-to-scan
  // odometry needs this and odometry.plane_through_nearest to register two identical sweeps to exactly zero
  // motion (0.8-5 mm, 0.02-0.07 deg per sweep without). Off: with range noise, driving roadway-loop 120 s,
  // scan-to-scan drift 3.5 % -> 6.6 % (both: 8.2 %): a single noisy point is a worse anchor than a centroid.
  bool less_flat_measured = false;
};

struct LinK3dConfig {
  // features.link3d.edge_threshold: smoothness above which a valid point is a LinK3D edge point.
  float edge_threshold = 0.2f;
  // features.link3d.edge_min_offset (m): noise floor as in LoamConfig, higher: keypoints should come from
  // strong, repeatable structure (depth jumps, corners seen at range), not from noise that happens to cluster.
  float edge_min_offset = 0.1f;
  // features.link3d.max_range (m): farther edge points are too sparse to cluster reliably.
  float max_range = 80.0f;
  // features.link3d.sectors: horizontal sectors the edge points are grouped into (paper eq. 2: 120).
  int sectors = 120;
  // features.link3d.cluster_radial_tol / cluster_xy_tol (m): a point joins a cluster of its sector if its
  // horizontal range differs from the cluster's mean by less than radial_tol and its horizontal position
  // lies within xy_tol of the cluster's mean (reference code: 0.4 / 0.3, but on |dx| and |dy| separately,
  // which depends on the sensor's yaw).
  float cluster_radial_tol = 0.4f;
  float cluster_xy_tol = 0.3f;
  // features.link3d.merge_radial_tol / merge_xy_tol (m): clusters of the same or neighbouring sectors
  // whose means agree this well (same two tests) are one object cut by a sector border (reference: 0.6 / 0.8).
  float merge_radial_tol = 0.6f;
  float merge_xy_tol = 0.8f;
  // features.link3d.min_cluster_points / min_cluster_rings: a merged cluster becomes a keypoint only with
  // this many points over this many distinct rings: a vertical structure, not noise on one scan line.
  // (The reference code asks 12 points but its merge bug duplicates points, so it effectively asks ~6.)
  int min_cluster_points = 8;
  int min_cluster_rings = 3;
  // features.link3d.min_keypoints: fewer keypoints set FeatureSet::kFewKeypoints (too few to match).
  int min_keypoints = 5;
  // features.link3d.bin_tolerance (m): two descriptor bins agree if both non-zero and closer than this.
  float bin_tolerance = 0.2f;
  // features.link3d.min_score: matches need at least this many agreeing bins (reference code: 3).
  int min_score = 3;
};

struct RansacConfig {
  // features.ransac.iterations: 3-point hypotheses tried.
  int iterations = 200;
  // features.ransac.inlier_threshold (m): a matched keypoint pair is an inlier if the transform brings
  // them this close. Cluster centroids move with the viewpoint by a few decimetres on real data.
  float inlier_threshold = 0.5f;
  // features.ransac.min_inliers: fewer inliers means no reliable transform (ok = false).
  int min_inliers = 5;
  // features.ransac.min_sample_area (m^2): a 3-point hypothesis whose triangle is smaller (nearly
  // collinear keypoints) fixes the rotation badly and is skipped.
  float min_sample_area = 0.25f;
  // features.ransac.robust_scale (m): Cauchy scale of the final weighted refit. Centroids that agree to
  // centimetres dominate; a centroid 0.3 m off (its cluster cut differently in the other sweep) gets weight 0.1.
  float robust_scale = 0.1f;
  // features.ransac.seed: fixed seed of the hypothesis sampler (results are deterministic).
  std::uint32_t seed = 42;
};

struct FeatureConfig {
  PreprocessConfig preprocess;
  DeskewConfig deskew;
  LoamConfig loam;
  LinK3dConfig link3d;
  RansacConfig ransac;
  // Threads of the stage (core/chunk_pool.hpp): rings scored in groups, then the LOAM selection, the LinK3D
  // keypoints and the sweep's thinning side by side. The same FeatureSet for any count. The feature stage is
  // the longest link of the chain every sweep waits for (feature stage -> odometry -> the next sweep's
  // deskew); with a core to spare it ends sooner: simulated HDL-64 replay 11.6 -> 10.6 ms a scan. Where both
  // cores are already busy (a VLP-16 replay, the mapper beside it) the wall time does not change, and the
  // stage's own thread shows less CPU than it costs (2.8 -> 2.1 ms): measure the stages with 1.
  int threads = 2;
};

// Keys "features.<group>.<field>" with type, range, unit and doc.
const ConfigTable<FeatureConfig>& featureConfigTable();
// Reads and validates the keys (throws ConfigError); missing keys keep the defaults.
FeatureConfig featureConfigFrom(const Config& c);
// R_lidar_imu from roll, pitch, yaw in degrees (as the key imu_rotation_rpy_deg gives them).
Eigen::Quaterniond rotationFromRpyDeg(const Eigen::Vector3f& rpy_deg);

}  // namespace adit
