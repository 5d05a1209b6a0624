// The process resources on STATUS (threads, open files, anonymous memory) follow what the process holds.
#include "runtime/resources.hpp"

#include <gtest/gtest.h>

#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <thread>

using namespace adit::runtime;

TEST(ProcessResources, CountThreadsFilesAndAnonymousMemory) {
  const ProcessResources before = readProcessResources();
  ASSERT_GE(before.threads, 1);
  ASSERT_GE(before.open_files, 3);  // stdin, stdout, stderr at least
  ASSERT_GT(before.anonymous_kb, 0);

  std::mutex mutex;
  std::condition_variable wake;
  bool done = false;
  std::thread waiting([&] {
    std::unique_lock<std::mutex> lock(mutex);
    wake.wait(lock, [&] { return done; });
  });
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  constexpr std::size_t kBytes = std::size_t{16} << 20;
  std::unique_ptr<char[]> block(new char[kBytes]);
  std::memset(block.get(), 1, kBytes);  // touched: resident

  const ProcessResources during = readProcessResources();
  EXPECT_EQ(during.threads, before.threads + 1);
  EXPECT_EQ(during.open_files, before.open_files + 1);
  EXPECT_GE(during.anonymous_kb, before.anonymous_kb + 15 * 1024);

  block.reset();
  std::fclose(file);
  {
    std::lock_guard<std::mutex> lock(mutex);
    done = true;
  }
  wake.notify_all();
  waiting.join();
  const ProcessResources after = readProcessResources();
  EXPECT_EQ(after.threads, before.threads);
  EXPECT_EQ(after.open_files, before.open_files);
  std::printf("threads %d -> %d, open files %d -> %d, anonymous %lld -> %lld kB\n", before.threads, during.threads,
              before.open_files, during.open_files, static_cast<long long>(before.anonymous_kb),
              static_cast<long long>(during.anonymous_kb));
}
