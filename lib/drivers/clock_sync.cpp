#include "drivers/clock_sync.hpp"

#include <algorithm>
#include <cmath>

namespace adit::drivers {

DeviceClockSync::DeviceClockSync(ClockSyncConfig config) : config_(config) {}

void DeviceClockSync::reset() {
  minima_.clear();
  have_current_ = false;
  fitted_ = false;
  slope_ = 0;
}

double DeviceClockSync::offsetAt(std::int64_t device_t) const {
  return intercept_ + slope_ * static_cast<double>(device_t - ref_t_);
}

void DeviceClockSync::refit() {
  // The open window's minimum is of a few samples only, so still high by their jitter: it is used only until
  // two windows have closed.
  std::deque<Minimum> points = minima_;
  if (points.size() < 2 && have_current_) points.push_back(current_);
  if (points.empty()) return;
  ref_t_ = points.back().device_t;
  if (points.size() < 3) {  // too short a baseline for a drift: the lowest minimum so far
    intercept_ = std::min_element(points.begin(), points.end(), [](const Minimum& a, const Minimum& b) {
                   return a.offset < b.offset;
                 })->offset;
    slope_ = 0;
  } else {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const double n = static_cast<double>(points.size());
    for (const Minimum& m : points) {
      const double x = static_cast<double>(m.device_t - ref_t_);
      sx += x;
      sy += m.offset;
      sxx += x * x;
      sxy += x * m.offset;
    }
    const double denominator = n * sxx - sx * sx;
    slope_ = denominator > 0 ? (n * sxy - sx * sy) / denominator : 0;
    intercept_ = (sy - slope_ * sx) / n;
  }
  fitted_ = true;
}

std::int64_t DeviceClockSync::stamp(std::int64_t device_t, std::int64_t host_t) {
  const double observed = static_cast<double>(host_t - device_t);
  const double max_jump = config_.max_jump_s * config_.ticks_per_s;
  if (fitted_ && std::abs(observed - offsetAt(device_t)) > max_jump) {
    // Far from the fit: one late sample (ignored) or a new device clock (followed once confirmed).
    far_in_a_row_ = std::abs(observed - far_offset_) <= max_jump ? far_in_a_row_ + 1 : 1;
    far_offset_ = observed;
    if (far_in_a_row_ < config_.jump_confirm) return hostStamp(device_t);
    ++jumps_;
    reset();
  }
  far_in_a_row_ = 0;
  const auto window = static_cast<std::int64_t>(config_.window_s * config_.ticks_per_s);
  // The fit changes only when a window closes, or with the open window's minimum while it is used (refit()).
  bool fit_changed = false;
  if (!have_current_ || device_t - window_start_ >= window || device_t < window_start_) {
    fit_changed = true;
    if (have_current_) minima_.push_back(current_);
    while (static_cast<int>(minima_.size()) > std::max(config_.windows - 1, 0)) minima_.pop_front();
    current_ = {device_t, observed};
    window_start_ = device_t;
    have_current_ = true;
  } else if (observed < current_.offset) {
    current_ = {device_t, observed};
    fit_changed = minima_.size() < 2;
  }
  if (fit_changed) refit();
  return hostStamp(device_t);
}

std::int64_t DeviceClockSync::hostStamp(std::int64_t device_t) {
  const auto out = static_cast<std::int64_t>(std::llround(device_t + offsetAt(device_t) - config_.transport_delay_s * config_.ticks_per_s));
  // A refit may move the line by microseconds; stamps must still advance.
  last_out_ = last_out_ == INT64_MIN ? out : std::max(out, last_out_ + 1);
  return last_out_;
}

}  // namespace adit::drivers
