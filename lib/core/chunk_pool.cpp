#include "core/chunk_pool.hpp"

#include <algorithm>

namespace adit {

ChunkPool::ChunkPool(int threads) {
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { work(); });
}

ChunkPool::~ChunkPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  start_.notify_all();
  for (std::thread& t : workers_) t.join();
}

std::pair<std::size_t, std::size_t> ChunkPool::range(std::size_t n, int chunks, int chunk) {
  const std::size_t c = static_cast<std::size_t>(std::max(1, chunks));
  const std::size_t i = static_cast<std::size_t>(std::max(0, chunk));
  return {n * i / c, n * (i + 1) / c};
}

void ChunkPool::run(std::size_t n, int chunks, const ChunkFn& fn) {
  chunks = std::max(1, chunks);
  if (workers_.empty() || chunks == 1) {
    for (int c = 0; c < chunks; ++c) {
      const auto [begin, end] = range(n, chunks, c);
      fn(c, begin, end);
    }
    return;
  }
  std::lock_guard<std::mutex> call(call_mutex_);
  std::size_t generation = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &fn;
    n_ = n;
    chunks_ = chunks;
    next_chunk_ = chunks_done_ = 0;
    error_ = nullptr;
    generation = ++generation_;
  }
  start_.notify_all();
  for (int chunk = 0; claim(generation, chunk);) runChunk(chunk);
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return chunks_done_ == chunks_; });
  job_ = nullptr;
  if (error_) std::rethrow_exception(error_);
}

bool ChunkPool::claim(std::size_t generation, int& chunk) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (generation != generation_ || !job_ || next_chunk_ >= chunks_) return false;
  chunk = next_chunk_++;
  return true;
}

void ChunkPool::runChunk(int chunk) {
  // job_, n_ and chunks_ stay fixed until every claimed chunk is done, so they are read without the lock.
  std::exception_ptr error;
  try {
    const auto [begin, end] = range(n_, chunks_, chunk);
    (*job_)(chunk, begin, end);
  } catch (...) {
    error = std::current_exception();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (error && !error_) error_ = error;
  if (++chunks_done_ == chunks_) done_.notify_all();
}

void ChunkPool::work() {
  std::size_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
    }
    const double cpu0 = threadCpuMs();
    for (int chunk = 0; claim(seen, chunk);) runChunk(chunk);
    worker_cpu_.add(threadCpuMs() - cpu0);
  }
}

}  // namespace adit
