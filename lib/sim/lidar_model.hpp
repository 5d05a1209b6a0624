// Spinning multi-beam lidar: sensor profiles and the sweep simulator.
//
// Timing, exactly as the real heads: the head spins clockwise seen from above (like Velodyne and RoboSense),
// firing one sequence of all channels per azimuth column, the channels of a sequence one firing slot apart.
// Every firing is ray-cast from the sensor pose at ITS OWN time, so motion during the sweep distorts the cloud
// the way a real sensor does. A sweep's utime is its last firing; dt = firing time - utime, in
// [-sweep_duration, 0]. The sweep starts and ends at the cut azimuth (default 180 deg = behind the robot, the
// usual driver setting), so the seam of the cloud is behind. Points are in the sensor frame at their firing time
// (not deskewed), in firing order, with ring = elevation rank (0 = lowest beam). No return (nothing within
// max_range, dropout) gives no point, like an unorganised driver cloud.
//
// Pose sampling: the pose is evaluated exactly every 8 firing sequences (0.44 ms for a VLP-16) and interpolated
// to first order for each firing in between (translation linear, rotation R_a (I + s [phi]x)): the error is
// second order in the motion over 0.44 ms, below 1e-6 m at 100 m range for these robots, so every firing
// effectively uses the pose at its own time.
// Noise per sweep comes from its own stream with a fixed number of draws per firing sequence, so the k-th sweep
// re-simulated with another pose function (e.g. frozen) gets the same noise, firing for firing.
#pragma once

#include "core/config.hpp"
#include "core/types.hpp"
#include "sim/scene.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace adit::sim {

struct LidarProfile {
  std::string name;
  std::vector<double> elevation_deg;  // per channel, in firing order within a sequence
  double rotation_hz = 10.0;
  int columns = 1800;            // firing sequences per revolution: azimuth step = 360 / columns
  double firing_slot = 2.304e-6; // s between consecutive channels of a sequence
  double min_range = 0.4;        // m, closer returns are discarded (also the robot's own body)
  double max_range = 100.0;      // m
  double range_sigma = 0.02;     // m, 1-sigma range noise (datasheet "accuracy +-3 cm" class)

  int channels() const { return static_cast<int>(elevation_deg.size()); }
  double sweepDuration() const { return 1.0 / rotation_hz; }
  double columnPeriod() const { return sweepDuration() / columns; }
  // ring index (0 = lowest elevation) of each channel
  std::vector<std::uint16_t> rings() const;
};

// Built-in profiles:
//  vlp16: Velodyne VLP-16, elevations -15..+15 deg by 2 deg fired interleaved (-15, 1, -13, 3, ...), 2.304 us
//         slots, 55.3 us sequences -> 1808 columns (0.199 deg) at 10 Hz, 100 m, sigma 2 cm.
//  rs16:  RoboSense RS-LiDAR-16, -15..+15 deg by 2 deg, channels 0-7 = -15..-1, 8-15 = +15..+1 (the rs_driver
//         order), 3 us slots, 1800 columns (0.2 deg) at 10 Hz, 150 m spec but 100 m here, sigma 2 cm.
//  hdl64: KITTI-like Velodyne HDL-64E, 64 beams from +2 to -24.9 deg (upper block +2..-8.33 by ~1/3 deg,
//         lower block -8.83..-24.9 by ~1/2 deg), 2000 columns (0.18 deg) at 10 Hz, 100 m, sigma 2 cm.
// Throws std::invalid_argument for another name.
LidarProfile lidarProfile(const std::string& name);

struct LidarNoiseConfig {
  double range_sigma = -1.0;      // m; < 0 = the profile's value
  double dropout = 0.01;          // probability a return is lost anywhere
  double grazing_dropout = 0.6;   // extra loss probability at grazing incidence (fades in below 10 deg)
  double dark_dropout = 0.3;      // extra loss for dark surfaces at max range (scales with range^2)
  bool dust = false;              // airborne dust / water spray near the sensor
  double dust_probability = 0.02; // per firing, when dust is on
  double dust_mean_range = 1.5;   // m beyond min_range, exponential
  double cut_azimuth_deg = 180.0; // sweep seam (deg, counter-clockwise from +x): behind the robot
  bool noiseless = false;         // exact ranges, no dropouts, no dust (tests)
};

// Keys "sim.lidar.<field>" with the defaults above.
LidarNoiseConfig lidarNoiseConfigFrom(const adit::Config& c);

// T_world_sensor at time t (seconds).
using PoseAt = std::function<Eigen::Isometry3d(double)>;

class LidarSimulator {
 public:
  LidarSimulator(LidarProfile profile, LidarNoiseConfig noise);

  // Simulates the sweep whose last firing is at time t_end (s, same clock as pose_at). The scan gets `utime`
  // and `seq`; noise comes from the random stream (seed, seq), so a sweep can be re-simulated on its own with
  // identical noise (e.g. with a different pose function).
  LidarScan simulate(const Scene& scene, const PoseAt& pose_at, double t_end, std::int64_t utime, std::int64_t seq,
                     std::uint64_t seed) const;
  // Same, reusing a caster's crop of the scene between sweeps (much faster for a stream of sweeps; the result
  // is identical to the overload above up to ties between coincident surfaces).
  LidarScan simulate(LocalRayCaster& caster, const PoseAt& pose_at, double t_end, std::int64_t utime,
                     std::int64_t seq, std::uint64_t seed) const;

  const LidarProfile& profile() const { return profile_; }
  const LidarNoiseConfig& noise() const { return noise_; }
  // Firing time of (column, channel) relative to the sweep's last firing (s, <= 0).
  double firingOffset(int column, int channel) const;

 private:
  // Measurement model for one firing: dust, dropouts, range noise, intensity. False = no return.
  bool measure(const Hit& hit, const Ray& ray, float noise, std::uint64_t bits, float& range, float& intensity) const;

  LidarProfile profile_;
  LidarNoiseConfig noise_;
  std::vector<std::uint16_t> rings_;
  std::vector<Eigen::Vector3f> directions_;  // unit ray per (column, channel), sensor frame, column-major
};

}  // namespace adit::sim
