#include "nodes/trajectory_log.hpp"

#include "core/byte_codec.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>

namespace adit::nodes {
namespace {

constexpr const char* kKind = "loop_closer_trajectory";
constexpr std::size_t kPoseBytes = 8 + 96;  // utime, pose

// Appends the poses of each record to `out` until it holds `length`; false if a record is malformed or the
// records do not end exactly there. `records_used` counts the records that made it up.
bool concatenate(const std::vector<std::string>& records, std::size_t length, Trajectory& out,
                 std::size_t& records_used) {
  records_used = 0;
  for (const std::string& record : records) {
    if (out.size() >= length) break;
    ByteReader r(record);
    const auto n = r.getCount(kPoseBytes);
    for (std::uint64_t i = 0; i < n && r.ok(); ++i) {
      StampedPose p;
      p.utime = r.get<std::int64_t>();
      p.pose = r.getPose();
      out.push_back(p);
    }
    if (!r.ok() || !r.atEnd()) return false;
    ++records_used;
  }
  return out.size() == length;
}

}  // namespace

TrajectoryLog::Chunk TrajectoryLog::unwritten() const {
  Chunk chunk;
  chunk.first = std::max(written_->load(), dropped_);
  chunk.poses.assign(tail_.begin() + static_cast<std::ptrdiff_t>(chunk.first - dropped_), tail_.end());
  return chunk;
}

void TrajectoryLog::write(const Chunk& chunk, const std::string& path, const std::string& run_id) {
  if (!log_.isOpen()) log_.create(path, kKind, run_id);
  if (chunk.first > logged_) throw std::runtime_error(path + " is behind its checkpoint");
  const std::size_t skip = logged_ - chunk.first;
  if (skip >= chunk.poses.size()) return;  // a later job already wrote them
  ByteWriter w;
  w.put<std::uint64_t>(chunk.poses.size() - skip);
  for (std::size_t i = skip; i < chunk.poses.size(); ++i) {
    w.put<std::int64_t>(chunk.poses[i].utime);
    w.putPose(chunk.poses[i].pose);
  }
  log_.append({w.bytes()});
  logged_ += chunk.poses.size() - skip;
  written_->store(logged_);
}

void TrajectoryLog::release() {
  if (tail_.empty()) return;
  // The newest pose always stays (back()). In batches: erasing from the front of the tail moves the rest.
  const std::size_t upto = std::min(written_->load(), size() - 1);
  if (upto < dropped_ + 1000) return;
  tail_.erase(tail_.begin(), tail_.begin() + static_cast<std::ptrdiff_t>(upto - dropped_));
  dropped_ = upto;
}

Trajectory TrajectoryLog::all(const std::string& path, const std::string& run_id) const {
  if (dropped_ == 0) return tail_;
  // Only records the writer finished are needed; one it is appending now is cut off as torn.
  const runtime::LoadedRecords loaded = runtime::loadRecords(path, kKind, run_id, SIZE_MAX);
  if (!loaded.error.empty()) throw std::runtime_error(loaded.error);
  Trajectory out;
  out.reserve(size());
  std::size_t used = 0;
  concatenate(loaded.records, dropped_, out, used);  // may end past dropped_ (a record the tail also holds)
  if (out.size() < dropped_)
    throw std::runtime_error(path + " holds " + std::to_string(out.size()) + " of the trajectory's first " +
                             std::to_string(dropped_) + " poses");
  out.resize(dropped_);
  out.insert(out.end(), tail_.begin(), tail_.end());
  return out;
}

std::string TrajectoryLog::restore(const std::string& path, const std::string& run_id, std::size_t length) {
  if (length == 0) return "";
  const runtime::LoadedRecords loaded = runtime::loadRecords(path, kKind, run_id, SIZE_MAX);
  if (!loaded.error.empty()) return loaded.error;
  Trajectory poses;
  std::size_t used = 0;
  if (!concatenate(loaded.records, length, poses, used))
    return path + " does not hold the " + std::to_string(length) + " poses the checkpoint names";
  try {
    log_.continueAfter(path, used);  // cut records written after the checkpoint
  } catch (const std::exception& e) {
    return e.what();
  }
  // The newest pose stays in memory (back()); the others are in the log.
  tail_.assign(1, poses.back());
  dropped_ = length - 1;
  logged_ = length;
  written_->store(length);
  return "";
}

}  // namespace adit::nodes
