#include "runtime/allocator.hpp"

#include <malloc.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>

namespace adit::runtime {

void keepFreedMemoryForReuse(std::size_t largest_heap_block) {
  // Blocks below largest_heap_block come from the heap (a 64-beam sweep with its copies is ~10 MB); up to 256 MB
  // of free heap top stays mapped. Both fixed values also switch off glibc's threshold adaptation, so the
  // behaviour does not depend on what was freed first.
  mallopt(M_MMAP_THRESHOLD, static_cast<int>(largest_heap_block));
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

void allocateFromOneHeap() { mallopt(M_ARENA_MAX, 1); }

int heapArenas() {
  char* text = nullptr;
  std::size_t size = 0;
  std::FILE* out = open_memstream(&text, &size);
  if (!out) return -1;
  const bool written = malloc_info(0, out) == 0;
  std::fclose(out);
  int heaps = 0;
  for (const char* p = text; written && (p = std::strstr(p, "<heap nr=")) != nullptr; ++p) ++heaps;
  std::free(text);
  return written ? heaps : -1;
}

MemoryUse returnFreeMemory() {
  MemoryUse use;
  const struct mallinfo2 info = mallinfo2();
  use.heap_in_use_kb = static_cast<std::int64_t>((info.uordblks + info.hblkhd) / 1024);
  use.heap_free_kb = static_cast<std::int64_t>(info.fordblks / 1024);
  malloc_trim(0);
  std::ifstream statm("/proc/self/statm");
  std::int64_t pages = 0, resident = 0;
  if (statm >> pages >> resident) use.resident_kb = resident * (sysconf(_SC_PAGESIZE) / 1024);
  return use;
}

}  // namespace adit::runtime
