// The recent IMU samples a node keeps for the sweeps it processes (deskew, rotation prior).
#pragma once

#include "core/types.hpp"
#include "msg/convert.hpp"

#include <deque>
#include <vector>

namespace adit::nodes {

class ImuBuffer {
 public:
  // Samples older than the newest by more than keep_s are dropped.
  explicit ImuBuffer(double keep_s) : keep_us_(static_cast<std::int64_t>(keep_s * 1e6)) {}

  void add(const adit::imu_t& m) {
    samples_.push_back(msg::fromMessage(m));
    while (!samples_.empty() && samples_.front().utime < m.header.utime - keep_us_) samples_.pop_front();
  }
  void clear() { samples_.clear(); }
  std::vector<ImuSample> samples() const { return {samples_.begin(), samples_.end()}; }

 private:
  std::int64_t keep_us_;
  std::deque<ImuSample> samples_;
};

}  // namespace adit::nodes
