// A parallel loop whose results do not depend on scheduling (the registrations' correspondence search, the
// feature stage): [0, n) is cut into `chunks` contiguous ranges by n and chunks alone; the caller and the
// worker threads take ranges until none is left. A caller that writes each range's results into that range's own slot and joins the slots in range
// order gets exactly the bytes one thread gives, whatever the thread count and whoever ran which range (so
// replays stay byte-identical). On a busy machine a worker that gets no core costs at most the range it
// holds: the caller takes every range the worker has not started.
//
// The workers are started once and wait between calls (a thread start per call would cost more than a small
// sweep's search). One call at a time: concurrent callers are serialised.
#pragma once

#include "core/thread_cpu.hpp"

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace adit {

class ChunkPool {
 public:
  // threads <= 1: no worker, run() calls every chunk on the caller's thread.
  explicit ChunkPool(int threads);
  ~ChunkPool();
  ChunkPool(const ChunkPool&) = delete;
  ChunkPool& operator=(const ChunkPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }
  // CPU time the worker threads spent on calls so far (ms; monitoring only): what the caller's own CPU time
  // does not show. A worker adds its share of a call just after its last chunk, so the newest call's may be
  // missing for a moment after run() returned.
  double workerCpuMs() const { return worker_cpu_.ms(); }

  // Range `chunk` of `chunks` nearly equal parts of [0, n): [begin, end).
  static std::pair<std::size_t, std::size_t> range(std::size_t n, int chunks, int chunk);

  // Calls fn(chunk, begin, end) once for each chunk 0 .. chunks-1, on the caller's thread or a worker, and
  // returns when all are done; an exception thrown by one is rethrown here (the others still run).
  using ChunkFn = std::function<void(int chunk, std::size_t begin, std::size_t end)>;
  void run(std::size_t n, int chunks, const ChunkFn& fn);

 private:
  void work();
  // Takes the next chunk of job `generation`; false when that job has none left (or is over).
  bool claim(std::size_t generation, int& chunk);
  void runChunk(int chunk);

  std::vector<std::thread> workers_;
  std::mutex call_mutex_;  // one run() at a time
  std::mutex mutex_;       // everything below
  std::condition_variable start_, done_;
  const ChunkFn* job_ = nullptr;
  std::size_t n_ = 0;
  int chunks_ = 0, next_chunk_ = 0, chunks_done_ = 0;
  std::size_t generation_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
  CpuTally worker_cpu_;
};

}  // namespace adit
