// The loop closer's per-sweep trajectory in a live run: ten poses a second for hours, needed whole only when a
// map is saved. Each checkpoint appends the poses since the previous one to an append-only log in the run
// folder (runtime/record_log.hpp) instead of rewriting all of them, and the poses the log holds leave memory;
// all() reads them back. Without a log (replay) every pose stays in memory.
//
// Threads: the stage's thread calls everything but write(), which runs on the checkpoint writer thread.
#pragma once

#include "core/types.hpp"
#include "runtime/record_log.hpp"

#include <atomic>
#include <memory>
#include <string>

namespace adit::nodes {

class TrajectoryLog {
 public:
  void push_back(const StampedPose& pose) { tail_.push_back(pose); }
  std::size_t size() const { return dropped_ + tail_.size(); }
  bool empty() const { return size() == 0; }
  const StampedPose& back() const { return tail_.back(); }  // a pose is released only once a newer one came
  std::size_t inMemory() const { return tail_.size(); }

  // What a checkpoint must find in the log: the poses from `first` on (those the log may lack); the
  // checkpoint names first + poses.size() as the trajectory's length.
  struct Chunk {
    std::size_t first = 0;
    Trajectory poses;
  };
  Chunk unwritten() const;
  // Writer thread: appends the part of `chunk` the log lacks as one record (creating the log at `path`).
  // Throws std::runtime_error naming the file; the log's earlier records stay valid.
  void write(const Chunk& chunk, const std::string& path, const std::string& run_id);
  // Drops from memory the poses the log holds (all but the newest). Cheap: call once a sweep.
  void release();
  // Every pose, the log's read back from `path`. Throws std::runtime_error if the log lacks some.
  Trajectory all(const std::string& path, const std::string& run_id) const;
  // Resume: the trajectory is the first `length` poses of the log at `path`, which continues after them.
  // "" or what is wrong (this object then unchanged).
  std::string restore(const std::string& path, const std::string& run_id, std::size_t length);

 private:
  Trajectory tail_;          // poses dropped_ .. size() - 1
  std::size_t dropped_ = 0;  // poses only in the log
  runtime::RecordLog log_;   // writer thread
  std::size_t logged_ = 0;   // writer thread: poses in the log
  std::shared_ptr<std::atomic<std::size_t>> written_ = std::make_shared<std::atomic<std::size_t>>(0);
};

}  // namespace adit::nodes
