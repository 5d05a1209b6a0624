#include "launch/restart_policy.hpp"

#include <algorithm>

namespace adit::launch {

std::optional<double> RestartPolicy::onExit(double now_s, double ran_s) {
  exits_.push_back(now_s);
  while (!exits_.empty() && exits_.front() < now_s - limits_.window_s) exits_.pop_front();
  if (static_cast<int>(exits_.size()) > limits_.max_restarts) return std::nullopt;
  if (ran_s >= limits_.healthy_after_s) backoff_s_ = limits_.backoff_initial_s;
  const double delay = backoff_s_;
  backoff_s_ = std::min(limits_.backoff_max_s, backoff_s_ * 2.0);
  return delay;
}

}  // namespace adit::launch
