// CPU time of the calling thread, for monitoring only (STATUS, timing reports): never an input of a stage,
// whose results must not depend on the clock.
#pragma once

#include <ctime>

namespace adit {

// CLOCK_THREAD_CPUTIME_ID in ms: what a thread costs on a loaded machine, where wall time also counts the
// other processes.
inline double threadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

}  // namespace adit
