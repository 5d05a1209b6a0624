// An append-only scratch file for what a live process keeps out of memory (keyframe clouds and keypoints, Scan
// Contexts): created (truncated) and unlinked at once, so it is a cache of this process's memory, gone when the
// process is; a restart reads its keyframes from the checkpoint instead. Not thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

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

}  // namespace adit
