// The loop closer's keyframe clouds: over a long run most of its memory (~30 kB each). In memory by default;
// pageTo(file) keeps only the newest `resident` clouds in memory and appends the older ones to a page file,
// read back when a loop job, the map or a checkpoint needs them. A live process then holds a few MB of clouds
// however much roadway it has mapped. A cloud read back is the one written, so paging changes no result.
#pragma once

#include "loop/compact_cloud.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace adit {

class KeyframeCloudStore {
 public:
  KeyframeCloudStore() = default;
  ~KeyframeCloudStore();
  KeyframeCloudStore(KeyframeCloudStore&& other) noexcept;
  KeyframeCloudStore& operator=(KeyframeCloudStore&& other) noexcept;
  KeyframeCloudStore(const KeyframeCloudStore&) = delete;
  KeyframeCloudStore& operator=(const KeyframeCloudStore&) = delete;

  void add(CompactCloud cloud);
  void drop(int k);  // keeps nothing of keyframe k's cloud (a revisit)
  // Only the slots with keep[k] stay, renumbered in order (keyframes merged out of the graph). A paged cloud
  // stays where it is in the page file.
  void retain(const std::vector<bool>& keep);
  std::size_t size() const { return slots_.size(); }
  bool empty(int k) const;
  // Keyframe k's cloud, from memory or the page file; an unreadable page gives an empty cloud (readErrors()).
  // Not thread-safe: the loop closer reads clouds on its own thread and hands copies to its jobs.
  CompactCloud cloud(int k) const;

  // Pages every cloud but the newest `resident` out to `path`, now and as clouds are added. The file is
  // created (truncated) and unlinked at once: it is a cache of this process's memory, gone when the process
  // is, and a restart reads its keyframes from the checkpoint instead. Throws std::runtime_error if it cannot
  // be created. A failed write (disk full) keeps the cloud in memory and is counted (pageErrors()).
  void pageTo(const std::string& path, std::size_t resident);

  std::size_t residentBytes() const;  // the clouds in memory and the per-keyframe slots
  std::size_t pagedClouds() const { return paged_; }
  std::uint64_t pageFileBytes() const { return static_cast<std::uint64_t>(end_); }
  std::size_t pageErrors() const { return page_errors_; }
  std::size_t readErrors() const { return read_errors_; }

 private:
  struct Slot {
    CompactCloud cloud;         // in memory (empty once paged out)
    std::int64_t offset = -1;   // in the page file, or -1
    std::uint32_t points = 0;   // of the cloud, wherever it is
    float step = 0.0f;
  };
  void pageOut();
  void close();

  std::vector<Slot> slots_;
  int fd_ = -1;
  std::int64_t end_ = 0;
  std::size_t resident_ = 0;
  std::size_t resident_bytes_ = 0;  // of the clouds in memory
  std::size_t next_to_page_ = 0;  // slots before it are paged out (or empty)
  std::size_t paged_ = 0;
  std::size_t page_errors_ = 0;
  mutable std::size_t read_errors_ = 0;
};

}  // namespace adit
