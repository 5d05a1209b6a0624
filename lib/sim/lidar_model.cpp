#include "sim/lidar_model.hpp"

#include "sim/rng.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace adit::sim {
namespace {
constexpr double kDeg = M_PI / 180.0;
constexpr int kPoseStride = 8;  // firing sequences between exact pose evaluations (0.44 ms for a VLP-16)
}

std::vector<std::uint16_t> LidarProfile::rings() const {
  std::vector<int> order(elevation_deg.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return elevation_deg[a] < elevation_deg[b]; });
  std::vector<std::uint16_t> ring(elevation_deg.size());
  for (std::size_t r = 0; r < order.size(); ++r) ring[order[r]] = static_cast<std::uint16_t>(r);
  return ring;
}

LidarProfile lidarProfile(const std::string& name) {
  LidarProfile p;
  p.name = name;
  if (name == "vlp16") {
    for (int i = 0; i < 16; ++i) p.elevation_deg.push_back(i % 2 == 0 ? -15.0 + i : static_cast<double>(i));
    // i even: -15, -13, ..., -1 ; i odd: 1, 3, ..., 15 (VLP-16 laser ids 0..15 fire in this order)
    p.firing_slot = 2.304e-6;
    p.columns = 1808;  // 0.1 s / 55.296 us
    p.min_range = 0.4;
  } else if (name == "rs16") {
    for (int i = 0; i < 8; ++i) p.elevation_deg.push_back(-15.0 + 2.0 * i);
    for (int i = 0; i < 8; ++i) p.elevation_deg.push_back(15.0 - 2.0 * i);
    p.firing_slot = 3.0e-6;
    p.columns = 1800;
    p.min_range = 0.4;
  } else if (name == "hdl64") {
    for (int i = 0; i < 32; ++i) p.elevation_deg.push_back(2.0 - (2.0 + 8.33) * i / 31.0);
    for (int i = 0; i < 32; ++i) p.elevation_deg.push_back(-8.83 - (24.9 - 8.83) * i / 31.0);
    p.firing_slot = 0.75e-6;
    p.columns = 2000;
    p.min_range = 0.9;
  } else {
    throw std::invalid_argument("sim: unknown lidar '" + name + "' (vlp16, rs16, hdl64)");
  }
  return p;
}

LidarNoiseConfig lidarNoiseConfigFrom(const adit::Config& cfg) {
  LidarNoiseConfig c;
  const std::string p = "sim.lidar.";
  c.range_sigma = cfg.get(p + "range_sigma", c.range_sigma);
  c.dropout = cfg.get(p + "dropout", c.dropout);
  c.grazing_dropout = cfg.get(p + "grazing_dropout", c.grazing_dropout);
  c.dark_dropout = cfg.get(p + "dark_dropout", c.dark_dropout);
  c.dust = cfg.get(p + "dust", c.dust);
  c.dust_probability = cfg.get(p + "dust_probability", c.dust_probability);
  c.dust_mean_range = cfg.get(p + "dust_mean_range", c.dust_mean_range);
  c.cut_azimuth_deg = cfg.get(p + "cut_azimuth_deg", c.cut_azimuth_deg);
  c.noiseless = cfg.get(p + "noiseless", c.noiseless);
  return c;
}

LidarSimulator::LidarSimulator(LidarProfile profile, LidarNoiseConfig noise)
    : profile_(std::move(profile)), noise_(noise) {
  const int C = profile_.columns, J = profile_.channels();
  if (C <= 0 || J <= 0 || J * profile_.firing_slot > profile_.columnPeriod() + 1e-12)
    throw std::invalid_argument("sim: lidar profile '" + profile_.name + "' has inconsistent timing");
  if (noise_.range_sigma >= 0.0) profile_.range_sigma = noise_.range_sigma;
  rings_ = profile_.rings();
  directions_.resize(static_cast<std::size_t>(C) * J);
  const double rev = profile_.sweepDuration();
  for (int c = 0; c < C; ++c) {
    for (int j = 0; j < J; ++j) {
      // Clockwise spin from the cut azimuth; the head keeps turning between the slots of a sequence.
      const double since_start = c * profile_.columnPeriod() + j * profile_.firing_slot;
      const double az = noise_.cut_azimuth_deg * kDeg - 2 * M_PI * since_start / rev;
      const double el = profile_.elevation_deg[j] * kDeg;
      directions_[static_cast<std::size_t>(c) * J + j] =
          Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)).cast<float>();
    }
  }
}

double LidarSimulator::firingOffset(int column, int channel) const {
  const int C = profile_.columns, J = profile_.channels();
  return -((C - 1 - column) * profile_.columnPeriod() + (J - 1 - channel) * profile_.firing_slot);
}

LidarScan LidarSimulator::simulate(const Scene& scene, const PoseAt& pose_at, double t_end, std::int64_t utime,
                                   std::int64_t seq, std::uint64_t seed) const {
  LocalRayCaster caster(scene);
  return simulate(caster, pose_at, t_end, utime, seq, seed);
}

namespace {

// Normal deviates in pairs by Marsaglia's polar method (no sin/cos). Its rejection loop depends only on the
// random numbers, never on the geometry, so a sweep's noise stays the same firing for firing whatever the poses.
void normalPairs(Rng& rng, float* out, int count) {
  for (int j = 0; j < count; j += 2) {
    double x, y, r2;
    do {
      x = 2.0 * rng.uniform() - 1.0;
      y = 2.0 * rng.uniform() - 1.0;
      r2 = x * x + y * y;
    } while (r2 >= 1.0 || r2 == 0.0);
    const double f = std::sqrt(-2.0 * std::log(r2) / r2);
    out[j] = static_cast<float>(x * f);
    out[j + 1] = static_cast<float>(y * f);
  }
}

// Sensor motion over a block of firing sequences: exact poses at both ends, first order in between.
struct PoseBlock {
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  Eigen::Vector3f p = Eigen::Vector3f::Zero(), dp = Eigen::Vector3f::Zero(), phi = Eigen::Vector3f::Zero();

  PoseBlock() = default;
  PoseBlock(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b)
      : R(a.linear().cast<float>()),
        p(a.translation().cast<float>()),
        dp((b.translation() - a.translation()).cast<float>()) {
    const Eigen::Matrix3d dR = a.linear().transpose() * b.linear();
    phi = 0.5 * Eigen::Vector3d(dR(2, 1) - dR(1, 2), dR(0, 2) - dR(2, 0), dR(1, 0) - dR(0, 1)).cast<float>();
  }
  // World ray of sensor direction d at fraction s in [0, 1] of the block (unit to ~1e-9: tiny rotation step).
  Ray ray(const Eigen::Vector3f& d, float s, float t_max) const {
    Ray r;
    r.origin = p + s * dp;
    r.dir = R * (d + s * phi.cross(d));
    r.t_max = t_max;
    return r;
  }
};

float uniform16(std::uint64_t bits, int k) {
  return (static_cast<float>((bits >> (16 * k)) & 0xFFFF) + 0.5f) * (1.0f / 65536.0f);
}

}  // namespace

bool LidarSimulator::measure(const Hit& hit, const Ray& ray, float noise, std::uint64_t bits, float& range,
                             float& intensity) const {
  const float min_range = static_cast<float>(profile_.min_range), max_range = static_cast<float>(profile_.max_range);
  range = 0.0f;
  // Dust: a return from a particle in front of the surface (bits: 16-bit uniforms 1 and 2; 3 = intensity).
  if (!noise_.noiseless && noise_.dust && uniform16(bits, 1) < noise_.dust_probability) {
    const float r_dust = min_range - static_cast<float>(noise_.dust_mean_range) * std::log(1.0f - uniform16(bits, 2));
    if (!hit.valid() || r_dust < hit.t) {
      range = r_dust;
      intensity = 2.0f + 6.0f * uniform16(bits, 3);
    }
  }
  if (range == 0.0f) {
    if (!hit.valid()) return false;
    const float cos_incidence = std::fabs(hit.normal.dot(ray.dir));
    if (!noise_.noiseless) {  // dropouts: everywhere, at grazing incidence, dark surfaces far away (uniform 0)
      const float grazing = std::max(0.0f, 1.0f - cos_incidence / static_cast<float>(std::sin(10.0 * kDeg)));
      const float far = hit.t / max_range;
      const float p_drop = static_cast<float>(noise_.dropout + noise_.grazing_dropout * grazing +
                                              noise_.dark_dropout * (1.0f - hit.reflectivity) * far * far);
      if (uniform16(bits, 0) < p_drop) return false;
    }
    range = noise_.noiseless ? hit.t : hit.t + static_cast<float>(profile_.range_sigma) * noise;
    intensity = 255.0f * hit.reflectivity * (0.35f + 0.65f * cos_incidence) +
                (noise_.noiseless ? 0.0f : 6.0f * (uniform16(bits, 3) - 0.5f));
  }
  intensity = std::clamp(intensity, 0.0f, 255.0f);
  return range >= min_range && range <= max_range;
}

LidarScan LidarSimulator::simulate(LocalRayCaster& caster, const PoseAt& pose_at, double t_end, std::int64_t utime,
                                   std::int64_t seq, std::uint64_t seed) const {
  const int C = profile_.columns, J = profile_.channels();
  LidarScan scan;
  scan.utime = utime;
  scan.seq = seq;
  scan.sensor = profile_.name;
  scan.num_beams = J;
  scan.sweep_duration = static_cast<float>(profile_.sweepDuration());
  scan.has_ring = true;
  scan.has_time = true;
  scan.deskewed = false;
  scan.points.reserve(static_cast<std::size_t>(C) * J);

  Rng rng = Rng::forStream(seed, Stream::LidarSweep, static_cast<std::uint64_t>(seq));
  const double period = profile_.columnPeriod(), span = kPoseStride * period;
  const float max_range = static_cast<float>(profile_.max_range);
  std::vector<float> channel_dt(J), noise(J + 1);
  for (int j = 0; j < J; ++j) channel_dt[j] = static_cast<float>(firingOffset(C - 1, j));

  caster.moveTo(pose_at(t_end).translation().cast<float>());
  const double t_first = t_end + firingOffset(0, 0);
  Eigen::Isometry3d pose_b = pose_at(t_first);
  PoseBlock block;
  for (int c = 0; c < C; ++c) {
    if (c % kPoseStride == 0) {
      const Eigen::Isometry3d pose_a = pose_b;
      pose_b = pose_at(t_first + (c + kPoseStride) * period);
      block = PoseBlock(pose_a, pose_b);
    }
    normalPairs(rng, noise.data(), J);  // a fixed number of normal pairs per sequence
    const float column_dt = static_cast<float>((c - (C - 1)) * period);
    const float column_s = static_cast<float>((c % kPoseStride) * period / span);
    for (int j = 0; j < J; ++j) {
      const Eigen::Vector3f& d = directions_[static_cast<std::size_t>(c) * J + j];
      const Ray ray = block.ray(d, column_s + static_cast<float>(j * profile_.firing_slot / span), max_range);
      const std::uint64_t bits = rng.next();  // four 16-bit uniforms for the measurement model
      float range, intensity;
      if (!measure(caster.intersect(ray), ray, noise[j], bits, range, intensity)) continue;
      LidarPoint pt;
      pt.p = range * d;
      pt.intensity = intensity;
      pt.ring = rings_[j];
      pt.dt = column_dt + channel_dt[j];
      scan.points.push_back(pt);
    }
  }
  return scan;
}

}  // namespace adit::sim
