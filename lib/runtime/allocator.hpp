// glibc's allocator, tuned once at process start for a pipeline that allocates and frees sweep-sized buffers
// (0.1-3 MB) every 100 ms.
#pragma once

#include <cstddef>
#include <cstdint>

namespace adit::runtime {

// Keeps freed memory in the heap for reuse instead of returning it to the kernel at once: by default glibc
// unmaps blocks above its (adaptive) mmap threshold and trims the heap top beyond 128 kB, so the next sweep's
// buffers come back as fresh pages, each a page fault and a zero fill. Measured on `adit replay` of 30 s of
// simulated VLP-16: 15 % less CPU, the same peak memory. Call before the first allocation that matters.
// Blocks from `largest_heap_block` bytes up are mapped per allocation and unmapped when freed.
constexpr std::size_t kShortRunHeapBlock = std::size_t{64} << 20;  // adit replay, the CLI: up to 64 MB reused
// A live stage runs for hours: its large temporaries grow with the run (the loop closer's graph copies for a
// loop job, its checkpoints, the solver's matrices), and each new one, a little larger than the last, no longer
// fits the hole the last one left in the heap. With 64 MB the loop closer's freed-but-kept memory grew by
// ~90 MB per hour of driving while its memory in use stayed flat (soak, STATUS memory_* counters). Blocks of
// 1 MB and up (above a VLP-16 sweep's buffers, so sweeps still reuse the heap) are mapped instead.
constexpr std::size_t kLongRunHeapBlock = std::size_t{1} << 20;
void keepFreedMemoryForReuse(std::size_t largest_heap_block = kShortRunHeapBlock);

// Every thread allocates from the main heap: glibc otherwise gives each new thread an arena of its own (a 64 MB
// reservation, grown and trimmed on its own). A live stage's worker threads (the loop closer's loop jobs, the
// search threads' index builds) then leave long-lived blocks in several heaps, and each heap fragments around
// them. Measured in two 30-minute soaks side by side: the loop closer's anonymous memory 11.5 -> 7.3 MB and its
// freed-but-kept heap 14.3 -> 7.1 MB at 20-30 min, the same memory in use. Threads now share the heap's lock
// for the allocations their per-thread cache does not serve (not measured on its own; in the two-hour soak
// every stage kept up at twice real time). Call before any thread starts: a thread already running keeps its
// arena.
void allocateFromOneHeap();
// Heaps (arenas) the allocator has made so far (glibc malloc_info), for tests and diagnostics.
int heapArenas();

struct MemoryUse {
  std::int64_t resident_kb = 0;      // the process's resident set (/proc/self/statm), after the trim
  std::int64_t heap_in_use_kb = 0;   // allocated and not freed (every arena, mmapped blocks included)
  std::int64_t heap_free_kb = 0;     // freed but kept by the allocator, before the trim
};

// Measures the heap, then hands the free memory of every arena back to the kernel (glibc malloc_trim). A live
// process calls it now and then (runNodeProcess: every 30 s, reported on STATUS as memory_*_kb), so what one
// burst of work freed is not kept for the rest of the run. Costs a few ms, and a page fault per page reused
// afterwards.
MemoryUse returnFreeMemory();

}  // namespace adit::runtime
