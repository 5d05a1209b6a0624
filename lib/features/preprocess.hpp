// Preprocessing of a raw sweep: drop unusable points, organise by ring and firing order, remove outliers.
#pragma once

#include "core/types.hpp"
#include "features/feature_config.hpp"
#include "features/ring_cloud.hpp"

#include <vector>

namespace adit::features {

// More beams than any spinning lidar has; rings at or beyond this are dropped as out of range.
constexpr int kMaxRings = 256;

struct PreprocessReport {
  int points_in = 0;
  int removed_invalid = 0;  // NaN / inf coordinates (or time)
  int removed_range = 0;    // outside [min_range, max_range], inside the body box, or on a ring beyond num_beams
  int removed_outlier = 0;  // radius outlier filter
  bool ring_derived = false;  // rings assigned from elevation (scan had none)
  bool time_derived = false;  // per-point time derived from azimuth (scan had none)
};

// The whole preprocessing chain: validity/range/body filter, ring and time assignment when missing,
// grouping by ring in firing order, radius outlier removal. Never fails: an empty input gives an empty cloud.
RingCloud preprocessScan(const LidarScan& scan, const PreprocessConfig& cfg, PreprocessReport* report);

// Ring index from elevation for scans without rings: num_rings equal bins over [min, max] elevation,
// clamped at the ends (0 = lowest beam).
int ringFromElevation(const Eigen::Vector3f& p, int num_rings, float min_elevation_deg, float max_elevation_deg);

// Per-point time (dt <= 0, relative to the last firing) for a spinning lidar without timestamps: the
// point at seam_azimuth fired at -sweep_duration and time grows linearly with the azimuth swept since.
float timeFromAzimuth(const Eigen::Vector3f& p, float seam_azimuth, float sweep_duration, bool clockwise);

// Voxel downsampling: one point per occupied voxel of size `leaf` (m), at the centroid of its points and
// with the ring / time / intensity of the first of them. Output in order of first occurrence (deterministic).
std::vector<LidarPoint> voxelDownsample(const std::vector<LidarPoint>& points, float leaf);

}  // namespace adit::features
