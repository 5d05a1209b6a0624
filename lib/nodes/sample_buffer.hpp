// The recent samples of a sensor stream a node keeps for the sweeps it processes: IMU (deskew, rotation
// prior), wheel odometry (motion along degenerate directions). Messages arrive in time order (the runtime's
// input checks drop a stamp that goes backwards; a re-synchronised stream reaches onTimeJump, which clears).
#pragma once

#include "core/types.hpp"
#include "msg/convert.hpp"

#include <deque>
#include <vector>

namespace adit::nodes {

template <class Msg, class Sample>
class SampleBuffer {
 public:
  // Samples older than the newest by more than keep_s are dropped.
  explicit SampleBuffer(double keep_s) : keep_us_(static_cast<std::int64_t>(keep_s * 1e6)) {}

  void add(const Msg& m) {
    samples_.push_back(msg::fromMessage(m));
    while (!samples_.empty() && samples_.front().utime < m.header.utime - keep_us_) samples_.pop_front();
  }
  void clear() { samples_.clear(); }
  bool empty() const { return samples_.empty(); }
  std::vector<Sample> samples() const { return {samples_.begin(), samples_.end()}; }

 private:
  std::int64_t keep_us_;
  std::deque<Sample> samples_;
};

using ImuBuffer = SampleBuffer<adit::imu_t, ImuSample>;
using WheelBuffer = SampleBuffer<adit::wheel_odom_t, WheelOdomSample>;

}  // namespace adit::nodes
