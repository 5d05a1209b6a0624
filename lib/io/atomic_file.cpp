#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "io/io_error.hpp"

namespace adit::io {
namespace {

std::string errnoText() { return std::strerror(errno); }

// fsync through a fresh descriptor: std::ofstream does not expose its own.
bool fsyncPath(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

std::string parentDirectory(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

// Removes the temp file unless the write was committed (also when `write` throws).
class TempFileGuard {
 public:
  explicit TempFileGuard(std::string tmp) : tmp_(std::move(tmp)) {}
  ~TempFileGuard() {
    if (!committed_) std::remove(tmp_.c_str());
  }
  TempFileGuard(const TempFileGuard&) = delete;
  TempFileGuard& operator=(const TempFileGuard&) = delete;
  void commit() { committed_ = true; }

 private:
  std::string tmp_;
  bool committed_ = false;
};

}  // namespace

std::string atomicTempPath(const std::string& path) {
  return path + ".tmp." + std::to_string(static_cast<long>(::getpid()));
}

bool writesInPlace(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode);
}

namespace {

// Opens `file` (created or truncated) and lets `write` fill it; WriteError names the file on any failure.
void streamTo(const std::string& file, const std::function<void(std::ostream&)>& write) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw WriteError("cannot create '" + file + "': " + errnoText());
  errno = 0;  // a failed stream keeps no error code; the failed write(2) behind it left one in errno
  write(out);
  out.flush();
  if (!out) {
    const int error = errno;
    throw WriteError("write to '" + file + "' failed: " + (error ? std::strerror(error) : "stream error (disk full?)"));
  }
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (writesInPlace(path)) return streamTo(path, write);
  const std::string tmp = atomicTempPath(path);
  TempFileGuard guard(tmp);
  streamTo(tmp, write);
  if (!fsyncPath(tmp, O_RDONLY)) throw WriteError("fsync of '" + tmp + "' failed: " + errnoText());
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw WriteError("cannot rename '" + tmp + "' to '" + path + "': " + errnoText());
  guard.commit();
  // The data is safe; a failed directory fsync only weakens durability across a power cut.
  fsyncPath(parentDirectory(path), O_RDONLY | O_DIRECTORY);
}

void writeFileAtomically(const std::string& path, const std::string& bytes) {
  writeFileAtomically(path, [&bytes](std::ostream& out) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
}

}  // namespace adit::io
