// A live stage's threads allocate from one heap (runtime/allocator.hpp), so a long run does not fragment a heap
// per thread.
#include "runtime/allocator.hpp"

#include <gtest/gtest.h>

#include <condition_variable>
#include <cstdlib>
#include <mutex>
#include <thread>
#include <vector>

using namespace adit::runtime;

namespace {

// Runs in a death test's fresh process (no heap of an earlier thread to reuse): starts `threads` threads that
// each allocate and stay alive until all have, then exits with the number of heaps they made.
[[noreturn]] void exitWithHeapsMadeByThreads(bool one_heap, int threads) {
  if (one_heap) allocateFromOneHeap();
  const int before = heapArenas();
  std::mutex mutex;
  std::condition_variable changed;
  int allocated = 0;
  std::vector<std::thread> running;
  for (int t = 0; t < threads; ++t)
    running.emplace_back([&, t] {
      std::vector<int> blocks(1000, t);  // a thread's first allocation is when glibc gives it a heap
      std::unique_lock<std::mutex> lock(mutex);
      ++allocated;
      changed.notify_all();
      changed.wait(lock, [&] { return allocated == threads; });
    });
  for (std::thread& thread : running) thread.join();
  std::exit(heapArenas() - before);
}

}  // namespace

TEST(AllocatorDeathTest, ThreadsOfALiveStageMakeNoHeapOfTheirOwn) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's allocator replaces glibc's heaps";
#endif
  ASSERT_GE(heapArenas(), 1);
  ::testing::GTEST_FLAG(death_test_style) = "threadsafe";
  // What the setting changes on this C library: three threads alive at once make three heaps ...
  EXPECT_EXIT(exitWithHeapsMadeByThreads(false, 3), ::testing::ExitedWithCode(3), "");
  // ... and none once a live stage's process has set it.
  EXPECT_EXIT(exitWithHeapsMadeByThreads(true, 3), ::testing::ExitedWithCode(0), "");
}
