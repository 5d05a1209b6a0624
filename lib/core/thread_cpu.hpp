// CPU time of the calling thread, for monitoring only (STATUS, timing reports): never an input of a stage,
// whose results must not depend on the clock.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <ctime>

namespace adit {

// CLOCK_THREAD_CPUTIME_ID in ms: what a thread costs on a loaded machine, where wall time also counts the
// other processes.
inline double threadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// Thread CPU time added up by any number of threads, read by another (a stage's helper threads for STATUS).
class CpuTally {
 public:
  void add(double ms) { us_.fetch_add(std::llround(ms * 1e3), std::memory_order_relaxed); }
  double ms() const { return static_cast<double>(us_.load(std::memory_order_relaxed)) * 1e-3; }

 private:
  std::atomic<std::int64_t> us_{0};
};

}  // namespace adit
