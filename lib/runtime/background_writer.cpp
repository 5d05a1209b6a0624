#include "runtime/background_writer.hpp"

namespace adit::runtime {

BackgroundWriter::BackgroundWriter() : thread_([this] { run(); }) {}

BackgroundWriter::~BackgroundWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

bool BackgroundWriter::submit(Job job) {
  bool replaced = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    replaced = pending_.has_value();
    pending_ = std::move(job);
  }
  wake_.notify_all();
  return !replaced;
}

void BackgroundWriter::flush() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return !busy_ && !pending_; });
}

std::vector<std::string> BackgroundWriter::takeErrors() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> out;
  out.swap(errors_);
  return out;
}

std::int64_t BackgroundWriter::succeeded() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return succeeded_;
}

void BackgroundWriter::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stopping_ || pending_; });
    if (!pending_) break;  // stopping, nothing left
    Job job = std::move(*pending_);
    pending_.reset();
    busy_ = true;
    lock.unlock();
    std::string error;
    try {
      error = job();
    } catch (const std::exception& e) {
      error = e.what();
    }
    lock.lock();
    busy_ = false;
    if (error.empty()) ++succeeded_;
    else errors_.push_back(error);
    idle_.notify_all();
  }
  idle_.notify_all();
}

}  // namespace adit::runtime
