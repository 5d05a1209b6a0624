// What a long-running process holds besides its heap, read from /proc/self (Linux), for STATUS: threads, open
// file descriptors and anonymous memory. A live process reports them with its memory every 30 s, so growth over
// hours shows on the bus (lcm-spy, the soak) and not only in an outside sampler.
#pragma once

#include <cstdint>

namespace adit::runtime {

struct ProcessResources {
  int threads = 0;                 // Threads: in /proc/self/status
  int open_files = 0;              // entries of /proc/self/fd (sockets, logs, page files)
  std::int64_t anonymous_kb = 0;   // RssAnon: resident heap, stacks and arenas (not the library code paged in)
};

// 0 for whatever cannot be read (another kernel, /proc not mounted): a missing figure, never an error.
ProcessResources readProcessResources();

}  // namespace adit::runtime
