// The loop closer's keyframe clouds and their LinK3D keypoints: over a long run most of its memory (~30 kB and a
// few kB each). In memory by default; pageTo(file) keeps only the newest `resident` keyframes' clouds and
// keypoints in memory and appends the older ones to a page file (loop/page_file.hpp), read back when a loop job,
// the map or a checkpoint needs them. A live process then holds a few MB of them however much roadway it has
// mapped. What is read back is what was written, so paging changes no result.
#pragma once

#include "loop/compact_cloud.hpp"
#include "loop/keyframe_keypoints.hpp"
#include "loop/page_file.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace adit {

class KeyframeCloudStore {
 public:
  // keypoints: null (or empty) = none.
  void add(CompactCloud cloud, KeyframeKeypointsPtr keypoints = nullptr);
  void drop(int k);  // keeps nothing of keyframe k's cloud and keypoints (a revisit)
  // Only the slots with keep[k] stay, renumbered in order (keyframes merged out of the graph). A paged cloud
  // stays where it is in the page file.
  void retain(const std::vector<bool>& keep);
  std::size_t size() const { return slots_.size(); }
  bool empty(int k) const;
  // Keyframe k's cloud, from memory or the page file; an unreadable page gives an empty cloud (readErrors()).
  // Not thread-safe: the loop closer reads clouds on its own thread and hands copies to its jobs.
  CompactCloud cloud(int k) const;
  // Keyframe k's keypoints (null: none, or an unreadable page, counted in readErrors()).
  KeyframeKeypointsPtr keypoints(int k) const;

  // Pages every keyframe but the newest `resident` out to `path`, now and as keyframes are added (see
  // PageFile). Throws std::runtime_error if the file cannot be created. A failed write (disk full) keeps the
  // keyframe in memory and is counted (pageErrors()).
  void pageTo(const std::string& path, std::size_t resident);

  std::size_t residentBytes() const;  // the clouds and keypoints in memory and the per-keyframe slots
  std::size_t pagedClouds() const { return queue_.paged(); }
  std::uint64_t pageFileBytes() const { return file_.size(); }
  std::size_t pageErrors() const { return queue_.errors(); }
  std::size_t readErrors() const { return read_errors_; }

 private:
  struct Slot {
    CompactCloud cloud;               // in memory (empty once paged out)
    KeyframeKeypointsPtr keypoints;   // in memory (null once paged out)
    std::int64_t offset = -1;         // in the page file: the cloud's counts, then the keypoints; or -1
    std::uint32_t points = 0;         // of the cloud, wherever it is
    std::uint32_t keypoint_bytes = 0; // of the keypoints in the page file
    float step = 0.0f;
  };
  static std::size_t bytesOf(const Slot& slot);
  void pageOut();
  PagingQueue::Outcome pageOne(Slot& slot);

  std::vector<Slot> slots_;
  PageFile file_;
  PagingQueue queue_;
  std::size_t resident_bytes_ = 0;  // of the clouds and keypoints in memory
  mutable std::size_t read_errors_ = 0;
};

}  // namespace adit
