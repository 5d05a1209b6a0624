// Writes files off the processing thread. A checkpoint must never stall a stage: with lcm-logger recording
// ~17 MB/s to the same disk, one fsync was measured to take seconds, and a stage that waits loses sweeps
// from its socket buffer (1,282 of 3,000 in a 300 s live run). Jobs run in order on one thread; a job not
// yet started is replaced by a newer one (a newer checkpoint supersedes it), so a slow disk costs
// checkpoint frequency, not input.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace adit::runtime {

class BackgroundWriter {
 public:
  using Job = std::function<std::string()>;  // returns "" or an error

  BackgroundWriter();
  ~BackgroundWriter();  // finishes the running and the pending job
  BackgroundWriter(const BackgroundWriter&) = delete;
  BackgroundWriter& operator=(const BackgroundWriter&) = delete;

  // Queues `job`; returns false if it replaced a job that had not started yet.
  bool submit(Job job);
  // Waits until nothing is running or pending.
  void flush();
  // Errors of finished jobs since the last call, and how many jobs succeeded in all.
  std::vector<std::string> takeErrors();
  std::int64_t succeeded() const;

 private:
  void run();

  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::optional<Job> pending_;
  bool busy_ = false, stopping_ = false;
  std::vector<std::string> errors_;
  std::int64_t succeeded_ = 0;
  std::thread thread_;
};

}  // namespace adit::runtime
