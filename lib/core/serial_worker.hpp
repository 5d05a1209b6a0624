// One worker thread that runs jobs strictly in the order they were posted, so that jobs which share state
// (the loop closer's accepted and pending loops) see it in a fixed order whatever the thread timing; started
// once, so a job a sweep costs no thread start (the odometry's background index builds). With threaded =
// false every job runs inside post(): the same results, one thread (tests, --threads 1).
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>

namespace adit {

class SerialWorker {
 public:
  explicit SerialWorker(bool threaded);
  ~SerialWorker();  // runs every job already posted, then stops
  SerialWorker(const SerialWorker&) = delete;
  SerialWorker& operator=(const SerialWorker&) = delete;

  void post(std::function<void()> job);
  bool threaded() const { return thread_.joinable(); }

 private:
  void run();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> jobs_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace adit
