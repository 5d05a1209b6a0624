// glibc's allocator, tuned once at process start for a pipeline that allocates and frees sweep-sized buffers
// (0.1-3 MB) every 100 ms.
#pragma once

#include <cstdint>

namespace adit::runtime {

// Keeps freed memory in the heap for reuse instead of returning it to the kernel at once: by default glibc
// unmaps blocks above its (adaptive) mmap threshold and trims the heap top beyond 128 kB, so the next sweep's
// buffers come back as fresh pages, each a page fault and a zero fill. Measured on `adit replay` of 30 s of
// simulated VLP-16: 15 % less CPU, the same peak memory. Call before the first allocation that matters.
void keepFreedMemoryForReuse();

struct MemoryUse {
  std::int64_t resident_kb = 0;      // the process's resident set (/proc/self/statm), after the trim
  std::int64_t heap_in_use_kb = 0;   // allocated and not freed (every arena, mmapped blocks included)
  std::int64_t heap_free_kb = 0;     // freed but kept by the allocator, before the trim
};

// Measures the heap, then hands the free memory of every arena back to the kernel (glibc malloc_trim). A live
// process calls it now and then (runNodeProcess: every 30 s, reported on STATUS as memory_*_kb): with the
// settings above, freed blocks otherwise stay mapped for good, so a long-running stage keeps the high-water
// mark of every temporary it ever made. Costs a few ms, and a page fault per page reused afterwards.
MemoryUse returnFreeMemory();

}  // namespace adit::runtime
