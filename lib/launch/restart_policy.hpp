// When to restart a process that ended unplanned, and when to stop trying: exponential back-off (1 s doubling
// to 30 s, afresh after a healthy run) and giving up after too many exits within a sliding window. Plain
// arithmetic on seconds of a monotonic clock, so it is tested without processes.
#pragma once

#include <deque>
#include <optional>

namespace adit::launch {

struct RestartLimits {
  int max_restarts = 5;          // give up at the (max_restarts+1)-th exit within window_s (0 = never restart)
  double window_s = 60.0;        // sliding window the exits are counted in
  double backoff_initial_s = 1.0;
  double backoff_max_s = 30.0;
  double healthy_after_s = 30.0;  // a run this long resets the back-off to its initial value
};

class RestartPolicy {
 public:
  explicit RestartPolicy(RestartLimits limits = {}) : limits_(limits), backoff_s_(limits.backoff_initial_s) {}

  // An unplanned exit at time now_s after the process ran for ran_s. Returns the delay before the next start,
  // or nullopt: give up.
  std::optional<double> onExit(double now_s, double ran_s);

  // Exits counted in the window at the last onExit() (for messages).
  int exitsInWindow() const { return static_cast<int>(exits_.size()); }
  const RestartLimits& limits() const { return limits_; }

 private:
  RestartLimits limits_;
  double backoff_s_;
  std::deque<double> exits_;  // times of the exits within the window
};

}  // namespace adit::launch
