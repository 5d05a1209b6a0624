#include "loop/page_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace adit {
namespace {

// pwrite or pread of the whole buffer (both may transfer less than asked); false on an error or end of file.
template <class Buffer, class Transfer>
bool transferAll(Transfer transfer, int fd, Buffer* data, std::size_t bytes, std::int64_t offset) {
  while (bytes > 0) {
    const ssize_t n = transfer(fd, data, bytes, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    bytes -= static_cast<std::size_t>(n);
    offset += n;
  }
  return true;
}

}  // namespace

PageFile::~PageFile() {
  if (fd_ >= 0) ::close(fd_);
}

PageFile::PageFile(PageFile&& other) noexcept { *this = std::move(other); }

PageFile& PageFile::operator=(PageFile&& other) noexcept {
  if (this == &other) return *this;
  if (fd_ >= 0) ::close(fd_);
  fd_ = std::exchange(other.fd_, -1);
  end_ = std::exchange(other.end_, 0);
  return *this;
}

PageFile PageFile::create(const std::string& path, const std::string& what) {
  PageFile file;
  file.fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (file.fd_ < 0) throw std::runtime_error("cannot create the " + what + " page file " + path + ": " + std::strerror(errno));
  ::unlink(path.c_str());
  return file;
}

std::int64_t PageFile::append(const void* data, std::size_t bytes) {
  if (fd_ < 0 || !transferAll(::pwrite, fd_, static_cast<const char*>(data), bytes, end_)) return -1;
  const std::int64_t offset = end_;
  end_ += static_cast<std::int64_t>(bytes);
  return offset;
}

bool PageFile::read(std::int64_t offset, void* data, std::size_t bytes) const {
  return fd_ >= 0 && transferAll(::pread, fd_, static_cast<char*>(data), bytes, offset);
}

}  // namespace adit
