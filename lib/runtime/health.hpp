// Counters and timing of one node: what the STATUS channel reports.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <string>

namespace adit::runtime {

struct Health {
  std::int64_t inputs = 0;
  std::int64_t outputs = 0;
  std::int64_t drops = 0;   // inputs skipped (out of order, duplicate, empty)
  std::int64_t errors = 0;  // inputs that could not be used (undecodable, invalid)
  std::map<std::string, std::int64_t> counters;  // named, e.g. "decode_error", "time_backwards"
  std::string last_error;
  std::int64_t last_input_utime = 0;
  double busy_s = 0;  // total processing time (monitoring only)
};

// Processing times over a sliding window, for p50 / p95 / max on STATUS.
class TimingWindow {
 public:
  explicit TimingWindow(std::size_t capacity = 200) : capacity_(capacity) {}
  // Replay keeps every sample (capacity 0 = unbounded) for its timing report.
  void setCapacity(std::size_t capacity) { capacity_ = capacity; }
  void add(double ms);
  // q in [0, 1]; 0 if empty.
  double quantile(double q) const;
  double max() const;
  std::size_t size() const { return samples_.size(); }

 private:
  std::size_t capacity_;
  std::deque<double> samples_;
};

}  // namespace adit::runtime
