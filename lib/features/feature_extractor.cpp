#include "features/feature_extractor.hpp"

#include "core/chunk_pool.hpp"
#include "features/link3d.hpp"
#include "features/loam_features.hpp"
#include "features/preprocess.hpp"
#include "features/smoothness.hpp"

namespace adit {
using namespace features;  // the stage's building blocks
namespace {

void copyReport(const PreprocessReport& rep, FeatureSet& out) {
  out.points_in = rep.points_in;
  out.removed_invalid = rep.removed_invalid;
  out.removed_range = rep.removed_range;
  out.removed_outlier = rep.removed_outlier;
}

LidarScan cloudHeader(const LidarScan& scan) {
  LidarScan c;
  c.utime = scan.utime;
  c.seq = scan.seq;
  c.sensor = scan.sensor;
  c.num_beams = scan.num_beams;
  c.sweep_duration = scan.sweep_duration;
  c.has_ring = true;  // rings assigned from elevation if the scan had none
  c.has_time = true;  // times derived from azimuth if the scan had none
  c.deskewed = scan.deskewed;
  return c;
}

}  // namespace

FeatureExtractor::FeatureExtractor(FeatureConfig cfg)
    : cfg_(std::move(cfg)), pool_(cfg_.threads > 1 ? std::make_shared<ChunkPool>(cfg_.threads) : nullptr) {}

double FeatureExtractor::helperCpuMs() const { return pool_ ? pool_->workerCpuMs() : -1.0; }

FeatureSet FeatureExtractor::process(const LidarScan& scan, const std::vector<ImuSample>& imu,
                                     const MotionPrior& motion, float cloud_voxel) const {
  FeatureSet out;
  out.utime = scan.utime;
  out.cloud = cloudHeader(scan);

  PreprocessReport rep;
  RingCloud rings = preprocessScan(scan, cfg_.preprocess, &rep);
  copyReport(rep, out);
  out.cloud.num_beams = rings.numRings();
  for (int r = 0; r < rings.numRings(); ++r)
    if (rings.ringSize(r) == 0) out.flags |= FeatureSet::kEmptyRing;
  if (rings.empty()) {
    out.flags |= FeatureSet::kEmptySweep | FeatureSet::kFewKeypoints;
    return out;
  }

  if (!scan.deskewed) {
    out.flags |= deskewPoints(rings.points, scan.utime, scan.sweep_duration, imu, motion, cfg_.deskew);
    out.cloud.deskewed = (out.flags & (FeatureSet::kDeskewImu | FeatureSet::kDeskewMotion)) != 0;
  }

  const PointScores scores = scorePoints(rings, cfg_.loam, pool_.get());
  // Three independent jobs on the scored sweep, each writing only its own result: the LOAM sets, the LinK3D
  // keypoints and descriptors, the thinned sweep (the first is the longest: the caller's thread takes it).
  LoamFeatures loam;
  std::vector<LidarPoint> thinned;
  const auto job = [&](int chunk, std::size_t, std::size_t) {
    if (chunk == 0) {
      loam = selectLoamFeatures(rings, scores, cfg_.loam);
    } else if (chunk == 1) {
      for (const LinK3dCluster& c : extractLinK3dClusters(rings, scores, cfg_.link3d)) out.keypoints.push_back(c.centroid);
      out.descriptors = computeLinK3dDescriptors(out.keypoints);
    } else {
      thinned = voxelDownsample(rings.points, cloud_voxel);
    }
  };
  const int jobs = cloud_voxel > 0.0f ? 3 : 2;
  if (pool_) pool_->run(static_cast<std::size_t>(jobs), jobs, job);
  else for (int chunk = 0; chunk < jobs; ++chunk) job(chunk, 0, 0);
  out.corner_sharp = std::move(loam.sharp);
  out.corner_less_sharp = std::move(loam.less_sharp);
  out.surf_flat = std::move(loam.flat);
  out.surf_less_flat = std::move(loam.less_flat);
  if (static_cast<int>(out.keypoints.size()) < cfg_.link3d.min_keypoints) out.flags |= FeatureSet::kFewKeypoints;

  out.cloud.points = cloud_voxel > 0.0f ? std::move(thinned) : std::move(rings.points);
  return out;
}

}  // namespace adit
