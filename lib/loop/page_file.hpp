// An append-only scratch file for what a live process keeps out of memory (keyframe clouds and keypoints, Scan
// Contexts): created (truncated) and unlinked at once, so it is a cache of this process's memory, gone when the
// process is; a restart reads its keyframes from the checkpoint instead. Not thread-safe.
#pragma once

#include "loop/keep_mask.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace adit {

class PageFile {
 public:
  PageFile() = default;
  ~PageFile();
  PageFile(PageFile&& other) noexcept;
  PageFile& operator=(PageFile&& other) noexcept;
  PageFile(const PageFile&) = delete;
  PageFile& operator=(const PageFile&) = delete;

  // Throws std::runtime_error naming the file and `what` it would hold.
  static PageFile create(const std::string& path, const std::string& what);
  bool isOpen() const { return fd_ >= 0; }

  // Appends the bytes; their offset, or -1 if the write failed (disk full: the file stays as it was).
  std::int64_t append(const void* data, std::size_t bytes);
  // Reads bytes written at `offset`; false on an error or a short file.
  bool read(std::int64_t offset, void* data, std::size_t bytes) const;
  std::uint64_t size() const { return static_cast<std::uint64_t>(end_); }

 private:
  int fd_ = -1;
  std::int64_t end_ = 0;
};

// Which entries of a growing list go to a page file: all but the newest `resident`, oldest first, each once. What
// the stores that page (keyframe clouds, Scan Contexts) share; how an entry is written is theirs.
class PagingQueue {
 public:
  enum class Outcome { kNothingToPage, kPaged, kFailed };

  // From the first entry again, keeping `resident` in memory (a new page file).
  void restart(std::size_t resident) {
    resident_ = resident;
    next_ = 0;
    paged_ = 0;
  }
  // Offers the entries due, oldest first, to page(i) -> Outcome. A failed write stops here and leaves entry i
  // first in line for the next call (counted in errors(): the entry stays in memory).
  template <class PageOne>
  void pageOut(std::size_t size, PageOne page) {
    while (size - next_ > resident_) {
      const Outcome outcome = page(next_);
      if (outcome == Outcome::kFailed) {
        ++errors_;
        return;
      }
      if (outcome == Outcome::kPaged) ++paged_;
      ++next_;
    }
  }
  // The entries with keep[i] false left the list (keyframes merged out): the line keeps its place.
  void retain(const std::vector<bool>& keep) { next_ = keptAmongFirst(keep, next_); }

  std::size_t paged() const { return paged_; }
  std::size_t errors() const { return errors_; }

 private:
  std::size_t resident_ = 0;
  std::size_t next_ = 0;  // entries before it are paged out (or had nothing to page)
  std::size_t paged_ = 0;
  std::size_t errors_ = 0;
};

}  // namespace adit
