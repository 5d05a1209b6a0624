#include "runtime/allocator.hpp"

#include <malloc.h>

namespace adit::runtime {

void keepFreedMemoryForReuse() {
  // Blocks up to 64 MB come from the heap (a 64-beam sweep with its copies is ~10 MB); up to 256 MB of free
  // heap top stays mapped. Both fixed values also switch off glibc's threshold adaptation, so the behaviour does
  // not depend on what was freed first.
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

}  // namespace adit::runtime
