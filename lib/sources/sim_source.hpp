// The roadway simulator as a message source: LIDAR_POINTS, IMU and GROUND_TRUTH in time order, for
// `adit sim` (to a log, or live over LCM). Keeps the ground-truth poses of the sweeps for the --gt file.
#pragma once

#include "core/types.hpp"
#include "msg/sweep_codec.hpp"
#include "runtime/source.hpp"
#include "sim/simulator.hpp"

#include <functional>
#include <memory>
#include <vector>

namespace adit::sources {

struct SimChannels {
  std::string lidar = "LIDAR_POINTS";
  std::string imu = "IMU";                    // "" = no IMU (a vehicle without one)
  std::string ground_truth = "GROUND_TRUTH";  // "" = do not publish
  std::string wheel_odom = "WHEEL_ODOM";      // published when the simulation has wheel odometry (sim.wheel.enabled)
  // false: sweeps as full-float point_cloud_t, the format of logs before lidar_scan_t (tests of old logs).
  bool compact_sweeps = true;
  // false: a sweep's message carries no bytes, only its channel and time, for a wrapper that sends the sweep
  // another way (SimLidarUdpSource: as the sensor's UDP packets); encoding it would be wasted.
  bool sweep_bytes = true;
};

// Sensor outages for fault tests: a stream publishes nothing from start_s (seconds of sensor time after the
// first message) for duration_s, then resumes (its sequence numbers show the gap, as a real driver's would).
struct SimStall {
  double start_s = 0, duration_s = 0;  // duration 0 = no stall
  bool covers(double t_s) const { return duration_s > 0 && t_s >= start_s && t_s < start_s + duration_s; }
};
struct SimStalls {
  SimStall lidar, imu;
};

// The simulated head's firing table (ring of slot k fires k * firing_slot after its column), for encodeSweep.
msg::FiringTable firingTableOf(const sim::LidarProfile& profile);

// LIDAR_POINTS as compact lidar_scan_t (firing-grid layout), IMU, WHEEL_ODOM (when simulated), GROUND_TRUTH
// (odometry_t, pose only).
class SimSource : public runtime::MessageSource {
 public:
  SimSource(const sim::SimConfig& config, SimChannels channels, SimStalls stalls = {});
  bool next(runtime::OutgoingMessage& message) override;
  const runtime::Health& health() const override { return health_; }
  double progress() const override;

  const sim::Simulator& simulator() const { return simulator_; }
  const SimChannels& channels() const { return channels_; }
  // Each observer is called with every sweep / IMU sample as it is published, in the order added (e.g. to
  // also write the run as sensor packets, `--pcap`, or as a bag, `--bag`).
  void addSweepObserver(std::function<void(const LidarScan&)> observer) { sweep_observers_.push_back(std::move(observer)); }
  void addImuObserver(std::function<void(const ImuSample&)> observer) { imu_observers_.push_back(std::move(observer)); }
  // T_world_lidar at each sweep's utime (its last firing), in the order published (stalled sweeps left out).
  const Trajectory& groundTruth() const { return truth_; }

 private:
  sim::Simulator simulator_;
  SimChannels channels_;
  SimStalls stalls_;
  std::int64_t first_utime_ = -1;
  std::size_t sweeps_ = 0;  // simulated, stalled or not (progress)
  msg::FiringTable firing_table_;
  runtime::Health health_;
  Trajectory truth_;
  std::optional<runtime::OutgoingMessage> pending_truth_;  // published right after its sweep
  std::int64_t imu_seq_ = 0, truth_seq_ = 0, wheel_seq_ = 0;
  std::vector<std::function<void(const LidarScan&)>> sweep_observers_;
  std::vector<std::function<void(const ImuSample&)>> imu_observers_;
};

}  // namespace adit::sources
